use hdl::for_tests::route_miso;

/// For every conversion pattern of up to 6 branches and every MISO
/// level, lane `j` captures the `j`-th converting branch's MISO, so a
/// slot's words sit in lanes `0..n` in branch order.
#[test]
fn lanes_capture_the_converting_branches_in_order() {
    for nb in 1..=6usize {
        let queue: Vec<Vec<usize>> = (0..nb).map(|j| (j..nb).collect()).collect();
        for act in 0..1u64 << nb {
            for miso in 0..1u64 << nb {
                let got = route_miso(&queue, act, miso);
                let on: Vec<usize> = (0..nb).filter(|b| act >> b & 1 == 1).collect();
                for (j, b) in on.iter().enumerate() {
                    assert_eq!(got >> j & 1, miso >> b & 1, "nb {nb} act {act:b} lane {j}");
                }
            }
        }
    }
}
