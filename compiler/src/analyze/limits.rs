//! What a bake may spend, checked before anything is baked: each setting is within its own
//! range, but their products are not (16 spot lights at `shadow_res = 8192` are 4 GiB of maps and
//! a billion texel rays; one medium at `media_volume_res = 512` is a billion shadow rays;
//! `voxel_res = 1024` is a 4 GiB grid before the line space is even estimated). The plan adds up
//! the bytes and rays of every stage its settings size (explicit values included) and refuses,
//! naming the product and the limit, what exceeds `--max-bake-memory` or `--max-bake-rays`.
//!
//! The limits come from the command line only, never the sidecar: a sidecar travels with the
//! asset, and an untrusted asset must not raise its own limits. They are process-wide, like the
//! import's file limits ([`crate::import::files::set_limits`]), since every caller of the plan
//! shares them; a library caller that sets none gets the defaults.

use std::sync::atomic::{AtomicU64, Ordering};

/// The default memory limit of the baked products the settings size: 1 GiB.
pub const DEFAULT_MAX_BAKE_MEMORY: u64 = 1 << 30;

/// The default limit of rays the settings ask for (shadow-map texels, light-visibility samples):
/// 2^25, about 15 s on two cores (a 4096² map for each of two spot lights, 21 point lights at
/// the default 1024, or a 128³ light-visibility volume, 8 samples a cell, for two lights).
pub const DEFAULT_MAX_BAKE_RAYS: u64 = 1 << 25;

static MAX_MEMORY: AtomicU64 = AtomicU64::new(DEFAULT_MAX_BAKE_MEMORY);
static MAX_RAYS: AtomicU64 = AtomicU64::new(DEFAULT_MAX_BAKE_RAYS);

/// Sets the limits (`--max-bake-memory`, `--max-bake-rays`).
pub fn set_bake_limits(memory: u64, rays: u64) {
    MAX_MEMORY.store(memory, Ordering::Relaxed);
    MAX_RAYS.store(rays, Ordering::Relaxed);
}

/// One thing a stage makes, as its settings size it.
#[derive(Debug, Clone)]
pub struct Product {
    /// What it is and which settings make it, e.g. "16 shadow maps of 8192x8192 (--shadow-res)".
    pub what: String,
    /// Bytes it holds while baking (at least its section's).
    pub bytes: u64,
    /// Rays traced to make it.
    pub rays: u64,
}

/// Products of a plan so far; [`Self::check`] after each one is added refuses as soon as the
/// sum exceeds a limit, before the stage that would spend it (or the next estimate) runs.
#[derive(Debug, Default)]
pub struct Spending {
    products: Vec<Product>,
}

impl Spending {
    /// Adds `p` and checks the sums against the limits; the error (a usage error) lists what
    /// adds up, largest first, and how to get under the limit.
    pub fn add(&mut self, p: Product) -> Result<(), String> {
        self.products.push(p);
        let (bytes, rays) = self
            .products
            .iter()
            .fold((0u64, 0u64), |(b, r), p| (b.saturating_add(p.bytes), r.saturating_add(p.rays)));
        let memory = MAX_MEMORY.load(Ordering::Relaxed);
        let max_rays = MAX_RAYS.load(Ordering::Relaxed);
        let over = if bytes > memory {
            Some((
                format!("{} of memory, over the {} of --max-bake-memory", mib(bytes), mib(memory)),
                (|p: &Product| p.bytes) as fn(&Product) -> u64,
                mib as fn(u64) -> String,
            ))
        } else if rays > max_rays {
            Some((
                format!("{} rays, over the {} of --max-bake-rays", count(rays), count(max_rays)),
                (|p: &Product| p.rays) as fn(&Product) -> u64,
                count as fn(u64) -> String,
            ))
        } else {
            None
        };
        let Some((total, key, show)) = over else { return Ok(()) };
        let mut parts: Vec<&Product> = self.products.iter().filter(|p| key(p) > 0).collect();
        parts.sort_by_key(|p| std::cmp::Reverse(key(p)));
        let list: Vec<String> = parts.iter().map(|p| format!("{} ({})", p.what, show(key(p)))).collect();
        Err(format!(
            "the bake settings ask for {total}: {}; lower those settings, or raise the limit if the \
             machine has it",
            list.join(", ")
        ))
    }
}

fn mib(b: u64) -> String {
    if b >= 10 << 20 { format!("{} MiB", b >> 20) } else { format!("{:.1} MiB", b as f64 / (1 << 20) as f64) }
}

fn count(n: u64) -> String {
    if n >= 10_000_000 { format!("{}M", n / 1_000_000) } else { n.to_string() }
}
