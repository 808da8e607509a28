use hdl::for_tests::{candidate, readable, rename};

#[test]
fn paths_read_as_blocks() {
    assert_eq!(
        candidate("slotforge_core$branches$12$rom", true, "_"),
        "slotforge_branch12_rom"
    );
    assert_eq!(
        candidate("slotforge_core$seqs$0", true, "_"),
        "slotforge_spi_seq0"
    );
    assert_eq!(
        candidate("slotforge_core$merge", true, "_"),
        "slotforge_merger"
    );
    assert_eq!(candidate("merge$ch$3", false, "_"), "merge_ch_3");
    assert_eq!(candidate("seqs$1$cs_n", false, "__"), "spi_seq1__cs_n");
}

#[test]
fn a_clash_takes_another_name() {
    let t = "module m(a$b, a_b);\nendmodule // m\n";
    let r = rename(t);
    assert_eq!(r, "module m(a__b, a_b);\nendmodule // m\n");
}

#[test]
fn registers_of_equal_text_share_a_module() {
    let dff = |n: &str, w: &str| {
        format!("module {n}(d,q,clock);\n    output reg  {w}q;\nendmodule // {n}\n")
    };
    let t = format!(
        "module top(x);\n    a$r a(.d(x));\n    b$r b(.d(x));\n    c$r c(.d(x));\nendmodule // top\n\n{}\n{}\n{}",
        dff("a$r", "[3:0] "),
        dff("b$r", ""),
        dff("c$r", "[3:0] ")
    );
    let r = readable(&t);
    assert!(!r.contains('$'), "{r}");
    assert_eq!(r.matches("module slotforge_dff4(").count(), 1, "{r}");
    assert_eq!(r.matches("module slotforge_dff1(").count(), 1, "{r}");
    assert_eq!(r.matches("slotforge_dff4 ").count(), 2, "{r}");
    assert_eq!(r.matches("endmodule").count(), 3, "{r}");
}
