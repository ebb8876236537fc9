//! Seeded mutations of small assets through the compile, in process (issue 40): the public glTF
//! samples of `tests/corpus/khronos` (as `.gltf`, and packed here as `.glb`), an OBJ with its MTL
//! library, and a sidecar. Each mutated case is imported, validated and planned; the `.gltf`
//! cases and every seventh case that plan are also baked. A case must end with a file or an error: never a panic (nor one the
//! glTF importer's guard turned into "please report"), within 10 s and 2 GiB of live allocations
//! (`util/held.rs`, this binary's allocator). A failing case is written to the temporary folder
//! with its seed, to replay.

use std::path::Path;
use std::time::{Duration, Instant};

use base64::Engine;
use kiln_compiler::raycheck::Rng;
use kiln_compiler::untrusted::{Case, Kind, bake, plan};

#[path = "util/gltf.rs"]
#[allow(dead_code)] // Only its GLB packer serves here.
mod gltf_builder;
#[path = "util/held.rs"]
mod held;

fn corpus(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/corpus/khronos")
        .join(name)
        .join(format!("{name}.gltf"));
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `gltf` (whose buffers are data URIs) as its JSON without the first buffer's URI and that
/// buffer's bytes: the parts of a GLB.
fn glb_parts(gltf: &[u8]) -> (serde_json::Value, Vec<u8>) {
    let mut json: serde_json::Value = serde_json::from_slice(gltf).unwrap();
    let uri = json["buffers"][0]["uri"].as_str().unwrap().to_string();
    let data = base64::engine::general_purpose::STANDARD.decode(uri.split_once(',').unwrap().1).unwrap();
    json["buffers"][0].as_object_mut().unwrap().remove("uri");
    (json, data)
}

/// One to four seeded edits of a glTF document's values, so that mutations reach past the JSON
/// parser: a value (chosen among all of them) becomes an extreme number, -1, 0, a string, an
/// empty array or object; a key is removed; an array element duplicated.
fn mutate_json(doc: &serde_json::Value, rng: &mut Rng) -> serde_json::Value {
    use serde_json::{Value, json};
    fn paths(v: &Value, at: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
        out.push(at.clone());
        let children: Vec<(String, &Value)> = match v {
            Value::Object(m) => m.iter().map(|(k, v)| (k.clone(), v)).collect(),
            Value::Array(a) => a.iter().enumerate().map(|(i, v)| (i.to_string(), v)).collect(),
            _ => Vec::new(),
        };
        for (k, c) in children {
            at.push(k);
            paths(c, at, out);
            at.pop();
        }
    }
    let mut doc = doc.clone();
    for _ in 0..1 + rng.below(4) {
        let mut all = Vec::new();
        paths(&doc, &mut Vec::new(), &mut all);
        // A depth first, then a value at it: the few top-level arrays (accessors, buffers,
        // nodes) are chosen as often as the many numbers deep in them.
        let deepest = all.iter().map(Vec::len).max().unwrap_or(0);
        let depth = 1 + rng.below(deepest.max(1));
        let at: Vec<&Vec<String>> = all.iter().filter(|p| p.len() == depth).collect();
        let path = at[rng.below(at.len())].clone();
        let Some((last, parent_path)) = path.split_last() else { continue };
        let mut parent = &mut doc;
        for k in parent_path {
            parent = match parent {
                Value::Object(m) => m.get_mut(k).unwrap(),
                Value::Array(a) => &mut a[k.parse::<usize>().unwrap()],
                _ => unreachable!(),
            };
        }
        let replacement = match rng.below(9) {
            0 => json!(4294967295u64),
            1 => json!(-1),
            2 => json!(0),
            3 => json!(1e38),
            4 => json!(2147483647),
            5 => json!("x"),
            6 => json!([]),
            7 => json!({}),
            _ => Value::Null,
        };
        match parent {
            Value::Object(m) if replacement.is_null() => {
                m.remove(last);
            }
            Value::Object(m) => {
                m.insert(last.clone(), replacement);
            }
            Value::Array(a) => {
                let i = last.parse::<usize>().unwrap();
                if replacement.is_null() {
                    let copy = a[i].clone();
                    a.insert(i, copy);
                } else {
                    a[i] = replacement;
                }
            }
            _ => {}
        }
    }
    doc
}

const OBJ: &str = "mtllib scene.mtl\n# a lit box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 -1\nvn 0 0 1\ng box\ns 1\nusemtl wall\nf 1/1/1 2/2/1 3/3/1 4/1/1\nf 5/1/2 6/2/2 7/3/2 8/1/2\n\
s off\nf 1 2 6 5\nf -4 -3 -2\nusemtl lamp\nf 4 3 7 8\nl 1 2\np 3\n";

const MTL: &str = "newmtl wall\nKd 0.7 0.6 0.5\nKs 0.04 0.04 0.04\nNs 200\nd 1\nmap_Kd -s 2 2 1 wood.png\nbump -bm 0.5 n.png\n\
newmtl lamp\nKd 0 0 0\nKe 4 4 3\nillum 2\nPr 0.3\nPm 0\n";

const SIDECAR: &str = "[camera]\nposition = [0.5, 0.5, 3.0]\ntarget = [0.5, 0.5, 0.0]\nvfov_degrees = 40.0\n\n\
[[light]]\nkind = \"spot\"\nposition = [0.5, 2.0, 0.5]\ndirection = [0.0, -1.0, 0.0]\nintensity = 5.0\nouter_cone_degrees = 40.0\n\n\
[[light]]\nkind = \"rect\"\nposition = [0.5, 1.5, 0.5]\ndirection = [0.0, -1.0, 0.0]\nsize = [0.2, 0.2]\nright = [1.0, 0.0, 0.0]\nintensity = 2.0\n\n\
[sky]\nradiance = [0.1, 0.1, 0.12]\n\n[[medium]]\nsigma_s = [0.05, 0.05, 0.05]\ng = 0.3\n\n\
[material.\"wall\"]\nroughness = 0.5\nmetallic = 0.0\n\n[bake]\nshadow_res = 64\nmedia_volume_res = 8\nprobe_rays = 16\nvoxel_res = 4\nshaft_res = 2\n";

// ------------------------------------------------------------------ mutations

/// Values that break readers: limits of integer types, non-finite and denormal floats, negative
/// counts, long digit strings.
const EXTREMES: [&str; 12] = [
    "-1",
    "0",
    "4294967295",
    "2147483647",
    "18446744073709551616",
    "1e38",
    "-1e38",
    "NaN",
    "inf",
    "1e-45",
    "99999999999999999999",
    "-0",
];

/// One to four seeded edits of `seed`: bit flips, bytes set to structural characters, ranges
/// deleted, duplicated or spliced from `other`, a number replaced by an extreme, a truncation.
fn mutate(seed: &[u8], other: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        if b.is_empty() {
            b.push(b'0');
        }
        let at = rng.below(b.len());
        match rng.below(7) {
            0 => b[at] ^= 1 << rng.below(8),
            1 => b[at] = b"\0\xff-9\"{[]},:/\\ #\n"[rng.below(16)],
            2 => {
                let end = (at + 1 + rng.below(64)).min(b.len());
                b.drain(at..end);
            }
            3 => {
                let end = (at + 1 + rng.below(256)).min(b.len());
                let copy = b[at..end].to_vec();
                let to = rng.below(b.len());
                b.splice(to..to, copy);
            }
            4 => {
                let from = rng.below(other.len());
                let end = (from + 1 + rng.below(128)).min(other.len());
                b.splice(at..at, other[from..end].iter().copied());
            }
            5 => {
                // The number at or after `at`, whole.
                if let Some(start) = b[at..].iter().position(u8::is_ascii_digit).map(|p| p + at) {
                    let end = b[start..]
                        .iter()
                        .position(|c| !(c.is_ascii_digit() || *c == b'.' || *c == b'e'))
                        .map_or(b.len(), |p| p + start);
                    b.splice(start..end, EXTREMES[rng.below(EXTREMES.len())].bytes());
                }
            }
            _ => b.truncate(at),
        }
    }
    b
}

// ------------------------------------------------------------------ the test

#[test]
fn seeded_mutations_of_small_assets_end_in_a_file_or_an_error_within_bounds() {
    let gltfs: Vec<Vec<u8>> = ["Triangle", "BoxVertexColors", "Cameras", "SimpleMorph"].map(corpus).to_vec();
    let docs: Vec<serde_json::Value> = gltfs.iter().map(|g| serde_json::from_slice(g).unwrap()).collect();
    let parts: Vec<(serde_json::Value, Vec<u8>)> = gltfs.iter().map(|g| glb_parts(g)).collect();
    let glbs: Vec<Vec<u8>> = parts.iter().map(|(j, b)| gltf_builder::glb(j, b)).collect();
    let dir = tempfile::tempdir().unwrap();
    // Unmutated, every seed compiles (else the mutations would test only the first check).
    for (kind, main) in gltfs.iter().map(|g| (Kind::Gltf, g)).chain(glbs.iter().map(|g| (Kind::Glb, g))) {
        let loaded = plan(dir.path(), &Case { kind, main, mtl: &[], sidecar: None }).expect("a seed plans");
        bake(&loaded).expect("a seed bakes");
    }
    let obj_case = Case {
        kind: Kind::Obj,
        main: OBJ.as_bytes(),
        mtl: MTL.as_bytes(),
        sidecar: Some(SIDECAR.as_bytes()),
    };
    bake(&plan(dir.path(), &obj_case).expect("the OBJ seed plans")).expect("the OBJ seed bakes");

    let cases = 2000;
    let (mut planned, mut baked, mut refused) = (0, 0, 0);
    let mut slowest = (Duration::ZERO, 0);
    let mut largest = (0usize, 0);
    for n in 0..cases {
        let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15 ^ (n as u64).wrapping_mul(0x1000_0000_01b3));
        // Cases by turn: glTF, GLB, OBJ, MTL, sidecar; glTF and GLB mutated in their values two
        // times in three, else in their bytes.
        let structured = rng.below(3) < 2;
        let (kind, main, mtl, sidecar) = match n % 5 {
            0 => {
                let (i, j) = (rng.below(gltfs.len()), rng.below(gltfs.len()));
                let main = if structured {
                    serde_json::to_vec(&mutate_json(&docs[i], &mut rng)).unwrap()
                } else {
                    mutate(&gltfs[i], &gltfs[j], &mut rng)
                };
                (Kind::Gltf, main, Vec::new(), None)
            }
            1 => {
                let (i, j) = (rng.below(glbs.len()), rng.below(glbs.len()));
                let main = if structured {
                    gltf_builder::glb(&mutate_json(&parts[i].0, &mut rng), &parts[i].1)
                } else {
                    mutate(&glbs[i], &glbs[j], &mut rng)
                };
                (Kind::Glb, main, Vec::new(), None)
            }
            2 => (Kind::Obj, mutate(OBJ.as_bytes(), MTL.as_bytes(), &mut rng), MTL.as_bytes().to_vec(), None),
            3 => (Kind::Obj, OBJ.as_bytes().to_vec(), mutate(MTL.as_bytes(), OBJ.as_bytes(), &mut rng), None),
            _ => (
                Kind::Obj,
                OBJ.as_bytes().to_vec(),
                MTL.as_bytes().to_vec(),
                Some(mutate(SIDECAR.as_bytes(), SIDECAR.as_bytes(), &mut rng)),
            ),
        };
        let case = Case { kind, main: &main, mtl: &mtl, sidecar: sidecar.as_deref() };
        let case_dir = dir.path().join(format!("case{n}"));
        std::fs::create_dir(&case_dir).unwrap();
        let before = held::start();
        let start = Instant::now();
        let outcome = std::panic::catch_unwind(|| {
            let loaded = plan(&case_dir, &case)?;
            if n % 5 == 0 || n % 7 == 0 { bake(&loaded).map(|_| true) } else { Ok(false) }
        });
        let took = start.elapsed();
        let peak = held::peak_since(before);
        let failed = match &outcome {
            Err(_) => Some("panicked".to_string()),
            Ok(Err(e)) if e.message.contains("please report") => {
                Some(format!("an internal error: {}", e.message))
            }
            _ if took > Duration::from_secs(10) => Some(format!("took {took:?}")),
            _ if peak > 2 << 30 => Some(format!("allocated {peak} bytes at once")),
            _ => None,
        };
        if let Some(why) = failed {
            let keep = std::env::temp_dir().join(format!("kiln-mutation-{n}"));
            std::fs::create_dir_all(&keep).unwrap();
            std::fs::write(keep.join("main"), &main).unwrap();
            std::fs::write(keep.join("scene.mtl"), &mtl).unwrap();
            if let Some(s) = &sidecar {
                std::fs::write(keep.join("scene.toml"), s).unwrap();
            }
            panic!("case {n} ({kind:?}) {why}; its files are in {}", keep.display());
        }
        match outcome {
            Ok(Ok(true)) => baked += 1,
            Ok(Ok(false)) => planned += 1,
            Ok(Err(e)) => {
                refused += 1;
                if std::env::var_os("KILN_MUTATION_ERRORS").is_some() {
                    eprintln!("case {n} {kind:?}: {}", e.message.chars().take(120).collect::<String>());
                }
            }
            Err(_) => unreachable!(),
        }
        slowest = slowest.max((took, n));
        largest = largest.max((peak, n));
        std::fs::remove_dir_all(&case_dir).ok();
    }
    eprintln!(
        "{cases} cases: {planned} planned, {baked} baked, {refused} refused; slowest case {} {:?}, largest {} {} MiB",
        slowest.1,
        slowest.0,
        largest.1,
        largest.0 >> 20
    );
    // The mutations must reach past the first check: some cases plan and bake, some are refused.
    assert!(planned + baked >= cases / 10 && refused >= cases / 10, "{planned} {baked} {refused}");
}
