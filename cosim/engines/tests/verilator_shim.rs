//! The Verilator build/cache/FFI path, on a stand-in module with the ports of
//! `slotforge_top` for the tiny mix (it only holds its reset values, so the
//! checker must report divergences).

use std::path::Path;

use engines::VerilatedDut;
use judge::{run_dut, RunOptions};

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::tools;

const STANDIN: &str = r#"
module slotforge_top(input clk, input rst, input [1:0] adc_miso,
  output reg [1:0] adc_cs_n, output reg [1:0] adc_sclk, output reg [5:0] mux_sel,
  output reg [2:0] mux_en, output reg sample_valid, output reg [2:0] sample_channel,
  output reg [13:0] sample_value);
  reg [15:0] n;
  always @(posedge clk) begin
    adc_cs_n <= 2'b11; adc_sclk <= 2'b11; mux_sel <= 6'd0; mux_en <= 3'b101;
    sample_valid <= 1'b0; sample_channel <= 3'd0; sample_value <= {12'd0, adc_miso};
    n <= rst ? 16'd0 : n + 16'd1;
  end
endmodule
"#;

#[test]
fn standin_builds_loads_caches_and_is_checked() {
    if !tools::require_tools(&["verilator", "g++"]) {
        return;
    }
    let cache = tempfile::tempdir().unwrap();
    std::env::set_var("SLOTFORGE_CACHE", cache.path());
    let s = lut_gen::synthesize(
        &lut_gen::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testkit/mixes/tiny.toml"),
        )
        .unwrap(),
    )
    .unwrap();
    let (mut dut, built) = VerilatedDut::new(STANDIN).unwrap();
    assert!(!built.cached);
    let r = run_dut(&s, &mut dut, 1, &RunOptions::default(), "verilator", None);
    assert!(!r.ok);
    // branch 0's first conversion after reset (docs/timing.md, "Start-up")
    let t0 = s
        .branch_instants_in_frame(0)
        .iter()
        .map(|i| i.cycle)
        .find(|&t| !s.skipped_at_startup(0, t))
        .unwrap();
    assert!(
        r.divergences
            .iter()
            .any(|d| d.signal == "adc_cs_n[0]" && d.cycle == t0),
        "{}",
        r.summary()
    );
    drop(dut);
    let (_, again) = VerilatedDut::new(STANDIN).unwrap();
    assert!(again.cached);
    assert_eq!(again.key, built.key);
}
