//! VCD checking: generated waveforms, their edge cases, and broken files.

use std::path::{Path, PathBuf};

use judge::write_run;
use judge::VcdError;
use judge::{Dut, ModelDut, RunOptions};
use judge::{FaultyDut, PinFault};

fn tiny() -> lut_gen::Schedule {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml");
    lut_gen::synthesize(&lut_gen::load(&p).unwrap()).unwrap()
}

fn write_vcd<D: Dut>(s: &lut_gen::Schedule, dut: &mut D, frames: u64, path: &Path) {
    write_run(path, s, dut, frames, &RunOptions::default(), (0, u64::MAX)).unwrap();
}

fn good_vcd(dir: &Path) -> (lut_gen::Schedule, PathBuf) {
    let s = tiny();
    let p = dir.join("good.vcd");
    write_vcd(&s, &mut ModelDut::new(&s), 3, &p);
    (s, p)
}

fn rewrite(src: &Path, dst: &Path, f: impl Fn(&str) -> String) {
    let t = std::fs::read_to_string(src).unwrap();
    std::fs::write(dst, f(&t)).unwrap();
}

#[test]
fn generated_vcd_passes() {
    let d = tempfile::tempdir().unwrap();
    let (s, p) = good_vcd(d.path());
    let r = judge::check_vcd(&s, &p, None).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.frames, 3);
    assert_eq!(r.samples, 30 - s.startup_skips());
    assert_eq!(r.cycles, 3 * 4000);
}

#[test]
fn faulty_vcd_fails_with_first_divergence() {
    let d = tempfile::tempdir().unwrap();
    let s = tiny();
    let p = d.path().join("bad.vcd");
    let mut dut = FaultyDut::new(&s, ModelDut::new(&s), PinFault::WrongSampleBit, 4100);
    write_vcd(&s, &mut dut, 3, &p);
    let r = judge::check_vcd(&s, &p, None).unwrap();
    assert!(!r.ok);
    let dv = &r.divergences[0];
    assert_eq!(dv.signal, "sample_value");
    assert_eq!(dv.frame, 1);
    assert!(dv.channel.is_some());
    assert!(dv.context.len() >= 4, "{:?}", dv.context);
    assert!(r.violations.iter().any(|v| v.rule == "sample-value"));
}

#[test]
fn timescale_does_not_matter() {
    let d = tempfile::tempdir().unwrap();
    let (s, p) = good_vcd(d.path());
    let q = d.path().join("ns.vcd");
    rewrite(&p, &q, |t| {
        t.replace("$timescale 1ps $end", "$timescale\n  1 ns\n$end")
    });
    let r = judge::check_vcd(&s, &q, None).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.cycles, 12000);
}

#[test]
fn missing_clock_is_inferred() {
    let d = tempfile::tempdir().unwrap();
    let (s, p) = good_vcd(d.path());
    let q = d.path().join("noclk.vcd");
    rewrite(&p, &q, |t| {
        t.lines()
            .filter(|l| *l != "0!" && *l != "1!" && !l.contains(" ! clk "))
            .map(|l| format!("{l}\n"))
            .collect()
    });
    let r = judge::check_vcd(&s, &q, None).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.frames, 3);
}

#[test]
fn icarus_style_shared_codes_and_short_vectors() {
    // A testbench scope and the DUT scope share identifier codes (as Icarus
    // writes them), vectors are written without leading zeros (`b0`).
    let d = tempfile::tempdir().unwrap();
    let (s, p) = good_vcd(d.path());
    let q = d.path().join("tb.vcd");
    rewrite(&p, &q, |t| {
        let (head, body) = t.split_once("$enddefinitions $end\n").unwrap();
        let start = head.find("$scope module slotforge_top $end").unwrap();
        let pre = &head[..start];
        let dut = &head[start..];
        let top = &dut[..dut.find("$scope module branch_").unwrap()];
        let vars: String = top
            .lines()
            .filter(|l| l.starts_with("$var"))
            .map(|l| format!("{l}\n"))
            .collect::<Vec<_>>()
            .concat();
        let dut = dut.replace("$scope module slotforge_top $end", "$scope module dut $end");
        format!(
            "{pre}$scope module tb $end\n{vars}{dut}$upscope $end\n$enddefinitions $end\n{body}"
        )
    });
    assert!(std::fs::read_to_string(&q).unwrap().contains("\nb0 "));
    let r = judge::check_vcd(&s, &q, None).unwrap();
    assert!(r.ok, "{}", r.summary());
    let r = judge::check_vcd(&s, &q, Some("tb.dut")).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert!(matches!(
        judge::check_vcd(&s, &q, Some("nowhere")),
        Err(VcdError::Ports { .. })
    ));
}

#[test]
fn x_on_miso_at_capture_is_a_violation() {
    let d = tempfile::tempdir().unwrap();
    let (s, p) = good_vcd(d.path());
    let q = d.path().join("x.vcd");
    // adc_miso has id code `#` (index 2): make every MISO change of branch bits x.
    rewrite(&p, &q, |t| {
        let mut n = 0;
        t.lines()
            .map(|l| {
                if l.ends_with(" #") && l.starts_with('b') {
                    n += 1;
                    if n == 40 {
                        return "bxx #\n".to_string();
                    }
                }
                format!("{l}\n")
            })
            .collect()
    });
    let r = judge::check_vcd(&s, &q, None).unwrap();
    assert!(!r.ok);
    assert!(
        r.violations.iter().any(|v| v.rule == "x-or-z"),
        "{}",
        r.summary()
    );
}

#[test]
fn broken_files_are_errors() {
    let d = tempfile::tempdir().unwrap();
    let (s, p) = good_vcd(d.path());
    let full = std::fs::read(&p).unwrap();
    // cut in the middle of a line
    let q = d.path().join("cut.vcd");
    let mut cut = full[..full.len() / 2].to_vec();
    while cut.last() == Some(&b'\n') {
        cut.pop();
    }
    std::fs::write(&q, &cut).unwrap();
    assert!(matches!(
        judge::check_vcd(&s, &q, None),
        Err(VcdError::Truncated { .. })
    ));
    // cut in the header
    std::fs::write(&q, &full[..200]).unwrap();
    assert!(matches!(
        judge::check_vcd(&s, &q, None),
        Err(VcdError::Truncated { .. })
    ));
    // garbage values, backwards time, undeclared ids
    for (from, to) in [
        ("\n1!\n", "\n1?!\n"),
        ("\n#2000", "\n#5"),
        ("\n0!\n", "\n0~~\n"),
        ("\nb0 ", "\nb012 "),
    ] {
        let t = String::from_utf8(full.clone())
            .unwrap()
            .replacen(from, to, 1);
        std::fs::write(&q, t).unwrap();
        let e = judge::check_vcd(&s, &q, None);
        assert!(
            matches!(e, Err(VcdError::Malformed { .. })),
            "{from:?}: {e:?}"
        );
        eprintln!("{}", e.unwrap_err());
    }
    // random byte flips never panic
    let mut seed = 0x1234_5678u64;
    for _ in 0..40 {
        let mut b = full.clone();
        for _ in 0..5 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let i = (seed % b.len() as u64) as usize;
            b[i] = (seed >> 32) as u8;
        }
        std::fs::write(&q, &b).unwrap();
        let _ = judge::check_vcd(&s, &q, None);
    }
    assert!(matches!(
        judge::check_vcd(&s, d.path().join("none.vcd"), None),
        Err(VcdError::Io(..))
    ));
}

#[test]
fn wrong_mix_is_a_port_error() {
    let d = tempfile::tempdir().unwrap();
    let (_, p) = good_vcd(d.path());
    let eskin = lut_gen::synthesize(
        &lut_gen::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../mixes/eskin34.toml"))
            .unwrap(),
    )
    .unwrap();
    let e = judge::check_vcd(&eskin, &p, None).unwrap_err();
    assert!(matches!(e, VcdError::Ports { .. }), "{e}");
}

/// A full dump also holds the gateware's inner core, whose ports have the same
/// names at their fixed maximum widths: the scope whose widths are the mix's wins.
#[test]
fn inner_module_with_same_port_names_does_not_confuse_scope_detection() {
    let d = tempfile::tempdir().unwrap();
    let (s, p) = good_vcd(d.path());
    let q = d.path().join("nested.vcd");
    rewrite(&p, &q, |t| {
        let core: String = [
            ("rst", 1),
            ("adc_miso", 8),
            ("adc_cs_n", 8),
            ("adc_sclk", 8),
            ("mux_sel", 24),
            ("mux_en", 64),
            ("sample_valid", 1),
            ("sample_channel", 8),
            ("sample_value", 14),
        ]
        .iter()
        .enumerate()
        .map(|(i, (n, w))| {
            format!(
                "$var wire {w} ~{} {n} [{}:0] $end\n",
                (b'A' + i as u8) as char,
                w - 1
            )
        })
        .collect();
        t.replacen(
            "$scope module slotforge_top $end\n",
            &format!(
                "$scope module slotforge_top $end\n$scope module core $end\n{core}$upscope $end\n"
            ),
            1,
        )
    });
    assert!(std::fs::read_to_string(&q)
        .unwrap()
        .contains("$scope module core"));
    let r = judge::check_vcd(&s, &q, None).unwrap();
    assert!(r.ok, "{}", r.summary());
    assert_eq!(r.samples, 30 - s.startup_skips());
    // Against another mix neither scope fits: say so rather than "ambiguous".
    let eskin = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../mixes/eskin34.toml");
    let other = lut_gen::synthesize(&lut_gen::load(&eskin).unwrap()).unwrap();
    match judge::check_vcd(&other, &q, None) {
        Err(e) => assert!(e.to_string().contains("another mix"), "{e}"),
        Ok(r) => panic!("accepted: {}", r.summary()),
    }
}
