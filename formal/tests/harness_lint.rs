//! Every harness `prove` generates is Verilog yosys reads: each preset and
//! test mix without a link, with a UART and with an AXI4-Stream, and random
//! mixes the same way (a 16-bit converter's records once gave the packet
//! parser a zero-width constant, `0'd0`, and `prove` of every UART mix with
//! an AD7689 stopped with exit 2).

use std::fmt::Write;

use testkit::tools;

#[test]
fn yosys_reads_the_harness_of_every_kind_of_mix() {
    if !tools::require_tool("yosys") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut script = String::new();
    let mut names = Vec::new();
    let mut mixes = crate::coverage::mixes();
    // a 16-bit converter's records on a UART fast enough for them
    let ad7689 = testkit::mix("cmd-ad7689");
    let text =
        std::fs::read_to_string(&ad7689).unwrap() + "\n[link]\nkind = \"uart\"\nbaud = 3_000_000\n";
    let mix = lut_gen::parse(&ad7689, &text).unwrap();
    mixes.push((
        "cmd-ad7689 + uart".into(),
        lut_gen::synthesize(&mix).unwrap(),
    ));
    for (i, (name, s)) in mixes.iter().enumerate() {
        let h = formal::generate(s).unwrap();
        let f = dir.path().join(format!("h{i}.v"));
        std::fs::write(&f, &h.verilog).unwrap();
        let _ = write!(
            script,
            "design -reset; read_verilog -formal {}; ",
            f.display()
        );
        names.push(name.clone());
    }
    let out = std::process::Command::new("yosys")
        .args(["-q", "-p", &script])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    // yosys names the file it stopped in: h<i>.v is mix i
    let which = (names.iter().enumerate())
        .find(|(i, _)| err.contains(&format!("h{i}.v")))
        .map(|(_, n)| n.as_str());
    assert!(out.status.success(), "{which:?}: {err}");
    assert!(!err.contains("Warning"), "{which:?}: {err}");
}
