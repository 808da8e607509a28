use judge::for_tests::find_boundary;

/// Samples at 100 + 250k (slices of 1000 cycles): the packet's records
/// fix its slice's start among the multiples of the step, and no
/// record, or records the stream does not hold, fix nothing.
#[test]
fn the_packet_records_place_its_slice() {
    let samples: Vec<(u64, u16, u16)> = (0..40).map(|k| (100 + 250 * k, 1, k as u16)).collect();
    let recs = |ks: std::ops::Range<u16>| ks.map(|k| (1, k)).collect::<Vec<_>>();
    // the slice of samples 8..12 starts in (1850, 2100]: on a grid of
    // 500 (the pins repeat every half slice) only 2000 fits
    assert_eq!(
        find_boundary(&samples, &recs(8..12), (0, 9000), 500, 1000),
        Some(2000)
    );
    // on a grid of 250 only 1750 holds 7..11
    assert_eq!(
        find_boundary(&samples, &recs(7..11), (0, 9000), 250, 1000),
        Some(1750)
    );
    // a slice whose start the samples do not fix on the step: on the
    // model's own grid (a whole slice) if it fits, else none
    let sparse: Vec<(u64, u16, u16)> = vec![(2300, 1, 1), (4300, 1, 2)];
    assert_eq!(
        find_boundary(&sparse, &[(1, 1)], (0, 9000), 250, 1000),
        Some(2000)
    );
    assert_eq!(
        find_boundary(&sparse, &[(1, 1)], (1900, 9000), 250, 1000),
        Some(2000)
    );
    // ... and none when that start lies before the join (2250 fits
    // after it, but so do 1500 to 2000 before it)
    assert_eq!(
        find_boundary(&sparse, &[(1, 1)], (2100, 9000), 250, 1000),
        None
    );
    // before the join, empty, or not in the stream
    assert_eq!(
        find_boundary(&samples, &recs(8..12), (2100, 9000), 500, 1000),
        None
    );
    assert_eq!(find_boundary(&samples, &[], (0, 9000), 500, 1000), None);
    assert_eq!(
        find_boundary(&samples, &[(2, 8)], (0, 9000), 500, 1000),
        None
    );
}
