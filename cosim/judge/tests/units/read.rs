use std::path::Path;

use judge::for_tests::set_chunk_bytes;
use judge::RunOptions;
use judge::{check_vcd_with, read_cycles, write_run, CheckOptions, CycleSink, ModelDut, Pins};
use lut_gen::Schedule;

/// Every cycle handed on, as text.
#[derive(Default)]
struct Log(Vec<String>);

impl CycleSink for Log {
    fn cycle(&mut self, rst: Option<bool>, p: &Pins, x: &Pins, miso: u64, mx: u64) {
        self.0.push(format!("{rst:?} {p:?} {x:?} {miso} {mx}"));
    }
}

fn read(s: &Schedule, path: &Path, chunk: usize) -> Result<Vec<String>, String> {
    set_chunk_bytes(chunk);
    let mut log = Log::default();
    let r = read_cycles(s, path, None, &mut log).map_err(|e| e.to_string());
    set_chunk_bytes(1 << 18);
    r.map(|_| log.0)
}

/// Cutting the body anywhere (inside a `$comment`, between a vector
/// value and its code on the next line) reads the same cycles and gives
/// the same errors as one piece.
#[test]
fn chunks_cut_anywhere_read_the_same() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml");
    let s = lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap();
    let d = tempfile::tempdir().unwrap();
    let vcd = d.path().join("w.vcd");
    let opts = RunOptions::default();
    write_run(&vcd, &s, &mut ModelDut::new(&s), 1, &opts, (0, 1_000)).unwrap();
    let text = std::fs::read_to_string(&vcd).unwrap();
    let body = text.find("$enddefinitions").unwrap();
    let (head, tail) = text.split_at(body);
    // A comment over lines, and a vector's code on the next line.
    let tail = tail.replacen("\n#", "\n$comment a\n#5 b\n$end\n#", 3);
    let at = tail.find("\nb").unwrap() + 1;
    let sp = at + tail[at..].find(' ').unwrap();
    let tail = format!("{}\n{}", &tail[..sp], &tail[sp + 1..]);
    let odd = d.path().join("odd.vcd");
    std::fs::write(&odd, format!("{head}{tail}")).unwrap();
    let whole = read(&s, &odd, 1 << 18).unwrap();
    assert!(whole.len() > 500);
    for chunk in [1, 7, 64, 1000] {
        assert_eq!(read(&s, &odd, chunk).unwrap(), whole, "chunk {chunk}");
    }
    // Broken files: the same error, at the same line.
    let n = head.len() + tail.len();
    for (name, t) in [
        ("cut", format!("{head}{}", &tail[..tail.len() * 2 / 3])),
        ("open comment", format!("{head}{tail}$comment x\n")),
        ("dangling", format!("{head}{tail}b1\n")),
        (
            "bad",
            format!(
                "{head}{}\n#999999999999 q!\n{}",
                &tail[..tail.len() / 2],
                &tail[tail.len() / 2..]
            ),
        ),
    ] {
        let f = d.path().join("broken.vcd");
        std::fs::write(&f, &t).unwrap();
        let want = read(&s, &f, 1 << 18).unwrap_err();
        let kind = if name == "bad" {
            "malformed"
        } else {
            "truncated"
        };
        assert!(want.contains(kind), "{name}: {want}");
        for chunk in [1, 7, 64, 1000] {
            assert_eq!(
                read(&s, &f, chunk).unwrap_err(),
                want,
                "{name}, chunk {chunk} of {n}"
            );
        }
    }
}

/// A VCD without `$dumpvars` (every port unknown until its first
/// change, `rst` never given a value) is read from its first change, as
/// a window: a clean one passes, whether cut at reset or later, and a
/// fault inside it still fails.
#[test]
fn a_vcd_without_dumpvars_is_read_from_its_first_change() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml");
    let s = lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap();
    let d = tempfile::tempdir().unwrap();
    let f = s.grid.frame_cycles;
    for (from, to) in [(0, 2 * f), (f, 4 * f), (f + 777, 3 * f + 5)] {
        let vcd = d.path().join("w.vcd");
        let opts = RunOptions::default();
        write_run(&vcd, &s, &mut ModelDut::new(&s), 4, &opts, (from, to)).unwrap();
        let text = std::fs::read_to_string(&vcd).unwrap();
        let a = text.find("$dumpvars").unwrap();
        let b = a + text[a..].find("$end").unwrap() + "$end\n".len();
        let bare = format!("{}{}", &text[..a], &text[b..]);
        assert!(!bare.contains("$dumpvars"));
        let nd = d.path().join("nd.vcd");
        std::fs::write(&nd, &bare).unwrap();
        let (v, _) = check_vcd_with(&s, &nd, None, CheckOptions::default()).unwrap();
        assert!(v.ok && v.cycles > f, "window {from}..{to}: {v:?}");
        // a CS edge a cycle late inside it: a fault the check still finds
        let code_of = |name: &str| {
            let l = bare
                .lines()
                .find(|l| l.contains(&format!(" {name} ")))
                .unwrap();
            l.split_whitespace().nth(3).unwrap().to_string()
        };
        let cs = code_of("adc_cs_n");
        let lines: Vec<&str> = bare.lines().collect();
        let k = lines
            .iter()
            .enumerate()
            .filter(|(_, l)| l.starts_with('b') && l.ends_with(&format!(" {cs}")))
            .map(|(k, _)| k)
            .nth(20)
            .unwrap();
        let mut bad = lines.clone();
        bad.remove(k);
        let bad = bad.join("\n") + "\n";
        std::fs::write(&nd, bad).unwrap();
        let r = check_vcd_with(&s, &nd, None, CheckOptions::default());
        assert!(
            !matches!(r, Ok((ref v, _)) if v.ok),
            "window {from}..{to}: a missing CS change passed"
        );
    }
}
