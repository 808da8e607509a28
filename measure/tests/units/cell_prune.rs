use measure::for_tests::needed_models;

const MODELS: &str = "`timescale 1ps / 1ps\n`define X 1\n\
    module SB_LUT4 (output O, input I0);\n  assign O = I0;\nendmodule\n\
    `ifdef ICE40_U\n\
    (* blackbox *)\n\
    module SB_SPRAM256KA (output O);\n  reg [15:0] mem [0:16383];\nendmodule\n\
    `endif\n\
    module SB_RAM40_4KNR (output O);\n  SB_RAM40_4K r (.O(O));\nendmodule\n\
    module SB_RAM40_4K (output O);\n  assign O = 0;\nendmodule\n\
    module SB_DFF (output Q);\nendmodule\n";

/// A used cell's model stays, and the model another kept model
/// instantiates; an unused one goes (`SB_DFF` is not `SB_DFFE`'s);
/// every line outside a module stays.
#[test]
fn only_the_models_a_netlist_reaches_are_kept() {
    let netlist = "SB_LUT4 #(.LUT_INIT(16'h0001)) l (.O(a), .I0(b));\n\
                   SB_RAM40_4KNR r (.O(c));\nSB_DFFE d (.Q(e));\n";
    let got = needed_models(MODELS, netlist);
    for kept in [
        "module SB_LUT4",
        "module SB_RAM40_4KNR",
        "module SB_RAM40_4K ",
        "`define X 1",
        "`ifdef ICE40_U\n`endif",
    ] {
        assert!(got.contains(kept), "{kept}:\n{got}");
    }
    assert!(!got.contains("SB_SPRAM256KA"), "{got}");
    // a dropped model's attribute goes with it, never left dangling
    assert!(!got.contains("blackbox"), "{got}");
    assert!(!got.contains("module SB_DFF "), "{got}");
}

/// A model written on one line (`module ... endmodule`, as ECP5's
/// `cells_ff.vh` in a newer yosys) is a module of its own: an unused one
/// goes alone, and the `` `endif`` after it stays.
#[test]
fn a_one_line_model_is_a_module_of_its_own() {
    let models = "module LUT4(input A, output Z);\n  assign Z = A;\nendmodule\n\
                  `ifndef NO_INCLUDES\n\
                  module FD1P3AX(input D, output Q); TRELLIS_FF f (.DI(D), .Q(Q)); endmodule\n\
                  module FD1P3AY(input D, output Q); TRELLIS_FF f (.DI(D), .Q(Q)); endmodule\n\
                  `endif\n\
                  module TRELLIS_FF(input DI, output Q);\n  assign Q = DI;\nendmodule\n\
                  module INV(input A, output Z);\n  // a name that ends like the keyword: z_endmodule\n  assign Z = !A;\nendmodule\n";
    let got = needed_models(
        models,
        "LUT4 l (.A(a), .Z(b));\nFD1P3AY d (.D(c), .Q(e));\n",
    );
    for kept in [
        "module LUT4",
        "module FD1P3AY",
        "module TRELLIS_FF",
        "`ifndef NO_INCLUDES\n",
        "`endif\n",
    ] {
        assert!(got.contains(kept), "{kept}:\n{got}");
    }
    assert!(!got.contains("FD1P3AX"), "{got}");
    // a word ending in `endmodule` does not end a model: unused, all of it goes
    assert!(!got.contains("assign Z = !A;"), "{got}");
}
