//! Proofs remembered by what they proved, so `build` can show a proof
//! without spending minutes on it again: the key is a hash of the harness,
//! the design's Verilog, the engine, this crate's version and a digest of
//! its source, so any change to the gateware, the schedule (through the
//! harness) or the flow misses.
//! Only proofs (`Proved`) are kept: a bounded or failed run is redone.

use std::path::{Path, PathBuf};

use crate::{Outcome, Proof, Solver};

/// 64-bit FNV-1a over `parts`, each followed by its length (so the split
/// between parts is part of the key).
fn fnv64(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |b: u8| {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    };
    for p in parts {
        p.iter().for_each(|&b| eat(b));
        (p.len() as u64).to_le_bytes().iter().for_each(|&b| eat(b));
    }
    h
}

/// The key of proving `design` against `harness` with `solver`.
pub fn key(harness: &str, design: &str, solver: Solver) -> String {
    let a = fnv64(&[
        env!("CARGO_PKG_VERSION").as_bytes(),
        env!("ENGINE_DIGEST").as_bytes(),
        solver.name().as_bytes(),
        harness.as_bytes(),
        design.as_bytes(),
    ]);
    // A second hash over the parts in another order: 128 bits in all.
    let b = fnv64(&[
        design.as_bytes(),
        harness.as_bytes(),
        solver.name().as_bytes(),
    ]);
    format!("{a:016x}{b:016x}")
}

/// The shared cache directory when `SLOTFORGE_CACHE` is set.
pub fn shared_dir() -> Option<PathBuf> {
    std::env::var_os("SLOTFORGE_CACHE").map(|d| PathBuf::from(d).join("proofs"))
}

fn file(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("{key}.json"))
}

/// The proof stored under `key` in the first of `dirs` that has one.
pub fn load(dirs: &[PathBuf], key: &str) -> Option<Proof> {
    dirs.iter().find_map(|d| {
        let text = std::fs::read_to_string(file(d, key)).ok()?;
        let p: Proof = serde_json::from_str(&text).ok()?;
        (p.result == Outcome::Proved).then_some(p)
    })
}

/// Keeps `p` under `key` in `dir` when it is a proof (written to a
/// temporary file, then renamed: a reader never sees half a file).
pub fn store(dir: &Path, key: &str, p: &Proof) -> Result<(), String> {
    if p.result != Outcome::Proved {
        return Ok(());
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let json = serde_json::to_string_pretty(p).expect("a proof serializes");
    let tmp = dir.join(format!(".{key}.json.tmp"));
    std::fs::write(&tmp, json).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, file(dir, key)).map_err(|e| format!("{}: {e}", dir.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_change_with_every_part() {
        let k = key("h", "d", Solver::Abc);
        assert_eq!(k, key("h", "d", Solver::Abc));
        assert_ne!(k, key("h", "d2", Solver::Abc));
        assert_ne!(k, key("h2", "d", Solver::Abc));
        assert_ne!(k, key("h", "d", Solver::Pdr));
        assert_ne!(key("ab", "c", Solver::Abc), key("a", "bc", Solver::Abc));
        assert_eq!(k.len(), 32);
    }

    /// The build script hashed the engine's source: 16 hex digits, not the
    /// empty hash (which an empty file list would give).
    #[test]
    fn the_key_carries_a_digest_of_the_engines_source() {
        let d = env!("ENGINE_DIGEST");
        assert_eq!(d.len(), 16);
        assert!(d.chars().all(|c| c.is_ascii_hexdigit()));
        assert_ne!(d, "cbf29ce484222325");
    }

    fn proof(not_covered: &[&str]) -> Proof {
        Proof {
            mix: "m".into(),
            solver: Solver::Symbolic,
            result: Outcome::Proved,
            depth: 10,
            properties: Vec::new(),
            seconds: 1.0,
            solver_seconds: 0.5,
            own_design: true,
            mode_sel: false,
            netlist: None,
            note: "n".into(),
            not_covered: not_covered.iter().map(|s| s.to_string()).collect(),
            netlist_caveats: Vec::new(),
            counterexample: None,
            cycle: None,
        }
    }

    /// A remembered proof carries what it did not cover; one stored before
    /// the list existed (no `not_covered` key) is not taken for a proof of
    /// the whole contract: it is not loaded at all.
    #[test]
    fn a_remembered_proof_keeps_its_not_covered_list() {
        let dir = tempfile::tempdir().unwrap();
        let dirs = [dir.path().to_path_buf()];
        store(dir.path(), "k1", &proof(&["the line"])).unwrap();
        let back = load(&dirs, "k1").expect("loads");
        assert_eq!(back.not_covered, vec!["the line".to_string()]);
        let mut old: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(file(dir.path(), "k1")).unwrap())
                .unwrap();
        old.as_object_mut().unwrap().remove("not_covered");
        std::fs::write(file(dir.path(), "k2"), old.to_string()).unwrap();
        assert!(load(&dirs, "k2").is_none());
    }
}
