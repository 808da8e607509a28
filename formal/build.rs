//! Hashes the engine's own source into `ENGINE_DIGEST`, part of a proof
//! cache key: a remembered proof's note, depth and time were made by this
//! code, so a change to the engine misses the cache (the crate's version
//! alone stays the same between releases).

use std::path::{Path, PathBuf};

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("formal/src is readable")
        .map(|e| e.expect("a directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

fn main() {
    println!("cargo:rerun-if-changed=src");
    let mut files = Vec::new();
    sources(Path::new("src"), &mut files);
    // FNV-1a over each file's path and text.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for f in &files {
        let text = std::fs::read(f).expect("a source file is readable");
        for b in f.to_string_lossy().bytes().chain(text) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    println!("cargo:rustc-env=ENGINE_DIGEST={h:016x}");
}
