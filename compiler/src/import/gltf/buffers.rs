//! The buffers a glTF names, read within bounds, with the zeros of accessors that have no data.

use std::path::{Path, PathBuf};

use ::gltf::Document;

use super::expansion_limit;
use super::spec_defaults;
use super::uri::{load_uri, short};
use crate::exit::{CliError, CliResult};
use crate::import::files::ReadError;

/// Every buffer of `doc`: the GLB chunk, a URI's file or data, or `zeros` (the buffer
/// `spec_defaults::fill` added); each at least as long as the file declares.
pub(super) fn load_buffers(
    doc: &Document,
    mut blob: Option<Vec<u8>>,
    zeros: Option<spec_defaults::ZeroBuffer>,
    file: &str,
    base: &Path,
    inputs: &mut Vec<PathBuf>,
) -> CliResult<Vec<Vec<u8>>> {
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for b in doc.buffers() {
        if let Some(z) = zeros.filter(|z| z.index == b.index()) {
            // The zeros of accessors without data (the last buffer): bounded by the file's own
            // buffers, as a sparse accessor without a view is.
            let (limit, why) = expansion_limit(buffers.iter().map(Vec::len).sum());
            if z.length > limit {
                return Err(CliError::input(format!(
                    "{file}: accessors without a buffer view (all zeros) would take {} bytes, more than \
                     such accessors may expand to ({why})",
                    z.length
                )));
            }
            buffers.push(vec![0; z.length]);
            continue;
        }
        let (data, name) = match b.source() {
            ::gltf::buffer::Source::Bin => {
                let data = blob.take().ok_or_else(|| {
                    CliError::input(format!(
                        "{file}: buffer {} refers to the GLB binary chunk, which is missing",
                        b.index()
                    ))
                })?;
                (data, "GLB binary chunk".to_string())
            }
            ::gltf::buffer::Source::Uri(uri) => {
                let what = format!("buffer {} ('{}')", b.index(), short(uri));
                let data = load_uri(uri, base, inputs, &what).map_err(|e| match e {
                    ReadError::Confined(e) => CliError::input(format!("{file}: {e}")),
                    ReadError::Unreadable(e) => CliError::input(format!("{file}: {what}: {e}")),
                })?;
                (data, format!("'{}'", short(uri)))
            }
        };
        if data.len() < b.length() {
            return Err(CliError::input(format!(
                "{file}: buffer {} ({name}) has {} bytes but the glTF declares {} (truncated?)",
                b.index(),
                data.len(),
                b.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}
