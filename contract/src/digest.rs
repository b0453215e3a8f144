//! Hashes as lowercase hex, written once for every program: fingerprints of configs,
//! catalogs and datasets, file sums, cache keys.

use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::Path;

/// Lowercase hex of `bytes` (two digits a byte).
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 of `bytes`, in hex (64 digits).
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// SHA-256 of the file at `path`, streamed, in hex.
pub fn sha256_file(path: &Path) -> std::io::Result<String> {
    hash_reader(Sha256::new(), std::fs::File::open(path)?)
}

/// Feeds everything `reader` yields (in 1 MiB blocks) into `hasher` and returns the
/// digest in hex; `hasher` may already hold a prefix (a git blob's header).
pub fn hash_reader<D: Digest>(mut hasher: D, mut reader: impl Read) -> std::io::Result<String> {
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = reader.read(&mut buf)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(hex(&hasher.finalize()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_digests() {
        let hello = "5891b5b522d5df086d0ff0b110fbd9d21bb4fc7163af34d08286a2e846f6be03";
        assert_eq!(sha256_hex(b"hello\n"), hello);
        assert_eq!(hex(&[0x00, 0x0f, 0xa0, 0xff]), "000fa0ff");
        let dir = std::env::temp_dir().join(format!("rh-digest-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("f");
        std::fs::write(&p, b"hello\n").unwrap();
        assert_eq!(sha256_file(&p).unwrap(), hello);
        // A prefix already in the hasher counts (empty input still gives a digest).
        let mut h = Sha256::new();
        h.update(b"hello\n");
        assert_eq!(hash_reader(h, &b""[..]).unwrap(), hello);
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(sha256_file(&p).is_err());
    }
}
