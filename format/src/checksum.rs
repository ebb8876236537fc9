//! Checksums and content hashes (both XXH3, seed 0; see `FORMAT.md`, "Checksums and hashes").

use xxhash_rust::xxh3::{Xxh3, xxh3_64, xxh3_128};

/// The checksum of a byte range: XXH3-64 with seed 0.
pub fn checksum64(bytes: &[u8]) -> u64 {
    xxh3_64(bytes)
}

/// A 128-bit content hash of the inputs and settings that produced a section (XXH3-128, stored
/// little-endian). It identifies a bake result for caching; it is not a security hash.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, PartialOrd, Ord)]
pub struct ContentHash(pub [u8; 16]);

impl ContentHash {
    /// Hash of one byte string.
    pub fn of(bytes: &[u8]) -> Self {
        Self(xxh3_128(bytes).to_le_bytes())
    }

    /// Lower-case hex, 32 digits.
    pub fn to_hex(&self) -> String {
        self.0.iter().map(|b| format!("{b:02x}")).collect()
    }
}

impl std::fmt::Display for ContentHash {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.to_hex())
    }
}

/// Builds a [`ContentHash`] from several labelled parts. Each part is framed by its label and
/// length, so that ("ab", "c") and ("a", "bc") hash differently.
#[derive(Clone, Default)]
pub struct ContentHasher(Xxh3);

impl std::fmt::Debug for ContentHasher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ContentHasher")
    }
}

impl ContentHasher {
    /// A fresh hasher.
    pub fn new() -> Self {
        Self(Xxh3::new())
    }

    /// Adds a labelled byte string.
    pub fn part(&mut self, label: &str, bytes: &[u8]) -> &mut Self {
        self.0.update(&(label.len() as u64).to_le_bytes());
        self.0.update(label.as_bytes());
        self.0.update(&(bytes.len() as u64).to_le_bytes());
        self.0.update(bytes);
        self
    }

    /// Adds another hash (e.g. of an upstream stage).
    pub fn hash(&mut self, label: &str, hash: &ContentHash) -> &mut Self {
        self.part(label, &hash.0)
    }

    /// The hash so far.
    pub fn finish(&self) -> ContentHash {
        ContentHash(self.0.digest128().to_le_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FORMAT.md's worked example: `ContentHash` stores the XXH3-128 value little-endian, so its
    /// bytes (and `to_hex`) are the reverse of the big-endian digest `xxhsum -H2` prints
    /// (xxhsum 0.8.1: `printf kiln | xxhsum -H2` → `29e4f6aff37a6f975bfb178850627e51`).
    #[test]
    fn content_hash_is_the_little_endian_xxh3_128() {
        let xxhsum = "29e4f6aff37a6f975bfb178850627e51";
        let h = ContentHash::of(b"kiln");
        assert_eq!(format!("{:032x}", u128::from_le_bytes(h.0)), xxhsum);
        assert_eq!(h.to_hex(), "517e62508817fb5b976f7af3aff6e429");
        let empty = ContentHash::of(b"");
        assert_eq!(format!("{:032x}", u128::from_le_bytes(empty.0)), "99aa06d3014798d86001c324468d497f");
    }
}
