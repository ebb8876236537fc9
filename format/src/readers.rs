//! Which of the player's techniques read the sections that only some techniques read, as
//! `kiln-play` flags: what `kiln plan` names when it says why a bake stage runs. The player's
//! technique catalogue is the source (each technique's `Needs`); the player's test
//! `the_format_names_the_readers_the_catalogue_has` fails when a technique starts or stops
//! reading one of these sections and this table is not updated with it.

/// The shadow maps (`SHDW`).
pub const SHADOW_MAPS: &[&str] = &["--shadows shadowmap", "--media toth"];

/// The media light-visibility volumes (`MVIS`).
pub const MEDIA_VISIBILITY: &[&str] = &["--media march"];

/// The line space's arrays (binary, candidates, PNMT, pre-illuminated records).
pub const LINE_SPACE: &[&str] = &["--shadows linespace", "--gi linespace"];

/// The irradiance probe volume (`PRBG`, `PRBS`, `PRBI`, `PRBV`).
pub const PROBES: &[&str] = &["--gi probes"];

/// `readers` as prose: `--a x`, `--a x and --b y`, `--a x, --b y and --c z`.
pub fn list(readers: &[&str]) -> String {
    match readers.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        Some((last, _)) => (*last).to_owned(),
        None => "no technique".to_owned(),
    }
}
