use hdl::emit;
use hdl::for_tests::{core_port_name, core_ports, link_text, LinkParams, CORE, LINK};
use lut_gen::{Layout, Role, TOP_MODULE};
use std::path::Path;

/// Two converters with a command word (one on each style) beside a
/// listening one.
const COMMAND_MIX: &str =
    "name = \"cmd\"\n[clock]\nhz = 48000000\n[frame]\nperiod_us = 1000\nslice_us = 1000\n\
    [[branch]]\nname = \"m\"\nadc = \"mcp3208\"\nmux = \"internal\"\n\
    [[branch]]\nname = \"l\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\n\
    [[branch]]\nname = \"a\"\nadc = \"ad7689\"\nmux = \"internal\"\n\
    [[channel]]\nname = \"m5\"\nbranch = \"m\"\nrate_hz = 2000\ninput = 5\n\
    [[channel]]\nname = \"l0\"\nbranch = \"l\"\nrate_hz = 1000\ninput = 0\n\
    [[channel]]\nname = \"a3\"\nbranch = \"a\"\nrate_hz = 1000\ninput = 3\n\
    [[channel]]\nname = \"a6\"\nbranch = \"a\"\nrate_hz = 2000\ninput = 6\n";

/// A mode mix's link module (UART and AXI4-Stream, 3 mode bits) has
/// the `mode` input, and passes `verilator --lint-only -Wall` and
/// `iverilog -Wall` on its own.
#[test]
fn a_mode_link_module_lints_clean() {
    if !testkit::tools::require_tools(&["verilator", "iverilog"]) {
        return;
    }
    let dir = std::env::temp_dir().join(format!("hdl-mode-link-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // 10 slices leave 12 bits of padding; 1,024 leave none
    for (axis, slices) in [(None, 10), (Some(link::Tlast::Frame), 1024)] {
        let lp = LinkParams {
            slice_cycles: 800,
            slots_per_slice: 4,
            slices_per_frame: slices,
            div: 16,
            parity: 1,
            stop_bits: 1,
            depth: 7,
            crc_init: link::format::CRC_INIT,
            axis,
            mode_bits: 3,
        };
        let text = link_text(lp);
        assert!(text.contains("input wire  [2:0] mode;"), "{text}");
        let f = dir.join(format!("{LINK}.v"));
        std::fs::write(&f, &text).unwrap();
        let lint = testkit::tools::run_ok(
            std::process::Command::new("verilator")
                .args(["--lint-only", "-Wall", "--top-module", LINK])
                .arg(&f),
        );
        let out = String::from_utf8_lossy(&lint.stderr).to_string();
        assert!(!out.contains("%Warning"), "{axis:?}: {out}");
        let ic = testkit::tools::run_ok(
            std::process::Command::new("iverilog")
                .args(["-g2005", "-Wall", "-o", "/dev/null"])
                .arg(&f),
        );
        let out = String::from_utf8_lossy(&ic.stderr).to_string();
        assert!(out.trim().is_empty(), "{axis:?}: {out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The core's ports are rust-hdl field names (`core/top.rs`), which cannot
/// be generated from the contract's table: this is where a port renamed
/// in `lut_gen::PORTS` without renaming the core's field fails.
#[test]
fn core_ports_are_the_contracts() {
    // a mix with a command word has `adc_mosi` on both, the others not
    for (name, text) in [
        ("eskin34.toml", include_str!("../../../mixes/eskin34.toml")),
        ("cmd.toml", COMMAND_MIX),
    ] {
        let m = lut_gen::parse(Path::new(name), text).unwrap();
        let s = lut_gen::synthesize(&m).unwrap();
        let l = Layout::new(&s);
        assert_eq!(l.width(Role::Mosi) > 0, name == "cmd.toml");
        let v = emit(&s, None).unwrap();
        let head = format!("module {CORE}(");
        let line = v
            .verilog()
            .lines()
            .find(|l| l.starts_with(&head))
            .expect("the core module");
        let ports: Vec<&str> = line[head.len()..]
            .trim_end_matches(");")
            .split(',')
            .collect();
        // and one beyond the contract: the timebase's slot starts, which the
        // link counts (wired inside the wrapper, never a pin)
        let want: Vec<&str> = core_ports(&l)
            .map(|p| core_port_name(p.role))
            .chain(["slot_tick"])
            .collect();
        assert_eq!(ports, want);
        // and the wrapper exposes exactly the contract's ports, in order
        let top = format!("module {TOP_MODULE} (");
        let decl: Vec<String> = v
            .verilog()
            .lines()
            .skip_while(|l| *l != top)
            .skip(1)
            .take_while(|l| *l != ");")
            .map(|l| {
                l.trim_end_matches(',')
                    .rsplit(' ')
                    .next()
                    .unwrap()
                    .to_string()
            })
            .collect();
        let names: Vec<String> = core_ports(&l).map(|p| p.name.to_string()).collect();
        assert_eq!(decl, names);
    }
}
