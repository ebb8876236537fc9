//! Where a glTF's buffers and images come from: data URIs, and files relative to the asset read
//! within `files`' bounds and confinement.

use std::path::{Path, PathBuf};

use base64::Engine;

use crate::import::files::ReadError;

/// A URI shortened for messages (data URIs can be megabytes long).
pub(super) fn short(uri: &str) -> String {
    if uri.len() > 48 {
        format!("{}…", &uri[..uri.char_indices().nth(40).map_or(uri.len(), |(i, _)| i)])
    } else {
        uri.into()
    }
}

/// Reads a data URI or a file relative to `base` (within the confinement; `what` names the
/// reference in its error).
pub(super) fn load_uri(
    uri: &str,
    base: &Path,
    inputs: &mut Vec<PathBuf>,
    what: &str,
) -> Result<Vec<u8>, ReadError> {
    let bad = |m: String| ReadError::Unreadable(m);
    if let Some(rest) = uri.strip_prefix("data:") {
        let (meta, data) = rest.split_once(',').ok_or_else(|| bad("malformed data URI (no comma)".into()))?;
        return if meta.ends_with(";base64") {
            base64::engine::general_purpose::STANDARD
                .decode(data.trim())
                .map_err(|e| bad(format!("malformed base64 in data URI: {e}")))
        } else {
            Ok(percent_decode(data).map_err(bad)?.into_bytes())
        };
    }
    if uri.contains("://") {
        return Err(bad(
            "external URLs are not fetched; download the file and refer to it by a relative path".into(),
        ));
    }
    let rel = percent_decode(uri).map_err(bad)?;
    let path = base.join(&rel);
    let bytes = crate::import::files::read_referenced(what, &path)?;
    if !inputs.contains(&path) {
        inputs.push(path);
    }
    Ok(bytes)
}

fn percent_decode(s: &str) -> Result<String, String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b.get(i + 1..i + 3).and_then(|h| std::str::from_utf8(h).ok());
            let v = hex.and_then(|h| u8::from_str_radix(h, 16).ok()).ok_or("malformed %-escape in URI")?;
            out.push(v);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "URI is not UTF-8 after %-decoding".to_string())
}
