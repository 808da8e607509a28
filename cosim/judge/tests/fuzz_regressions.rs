//! Every input the fuzzer (`make fuzz-vcd`, docs/fuzzing.md) found to panic
//! or hang the VCD reader is kept in `tests/data/fuzz/` as
//! `<mix>__<what>-<hash>.vcd`; each must now give a clean error, quickly.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn mix_for(vcd: &Path) -> PathBuf {
    let name = vcd.file_name().unwrap().to_str().unwrap();
    let stem = name.split("__").next().unwrap();
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    [here.join("../../mixes"), here.join("../../testkit/mixes")]
        .iter()
        .map(|d| d.join(format!("{stem}.toml")))
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("no mix `{stem}.toml` for {}", vcd.display()))
}

#[test]
fn fuzz_found_inputs_are_clean_errors() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "vcd"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    for f in files {
        let mix = lut_gen::load(&mix_for(&f)).unwrap();
        let s = lut_gen::synthesize(&mix).unwrap();
        let t0 = Instant::now();
        let r = std::panic::catch_unwind(|| judge::check_vcd(&s, &f, None));
        let took = t0.elapsed();
        match r {
            Err(_) => panic!("{}: the VCD reader panicked", f.display()),
            Ok(Ok(rep)) => panic!("{}: accepted ({})", f.display(), rep.summary()),
            Ok(Err(e)) => {
                let msg = e.to_string();
                assert!(msg.contains(f.to_str().unwrap()), "{msg}");
                eprintln!("{msg}");
            }
        }
        assert!(
            took < Duration::from_secs(5),
            "{}: took {took:?}",
            f.display()
        );
    }
}
