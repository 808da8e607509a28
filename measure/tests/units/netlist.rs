use measure::for_tests::hollow_cells;

#[test]
fn cells_without_behaviour_are_found() {
    let used = ["SB_LUT4", "DP16KD", "WRAP", "GONE"];
    let models = "module SB_LUT4 (output O, input I0);\n  assign O = I0;\nendmodule\n\
                  module DP16KD(\n  input A, output B\n);\n  parameter X = 1;\nendmodule\n\
                  module WRAP (input A, output B);\n  SB_LUT4 l (.O(B), .I0(A));\nendmodule\n";
    assert_eq!(hollow_cells(&used, models), ["DP16KD", "GONE"]);
}
