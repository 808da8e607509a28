use hdl::for_tests::SlotLogic;

/// A small deterministic generator (no dependency for a unit test).
fn next(x: &mut u64) -> u64 {
    *x ^= *x << 13;
    *x ^= *x >> 7;
    *x ^= *x << 17;
    *x
}

/// Every reachable word equals the table's, for random tables of
/// random grids: regular ones (built from the slot and slice) and
/// arbitrary ones.
#[test]
fn logic_equals_the_table_on_random_tables() {
    let mut x = 0x9e37_79b9_7f4a_7c15;
    for round in 0..200 {
        let sps = 1 + (next(&mut x) % 40) as usize;
        let k = 1 + (next(&mut x) % 12) as usize;
        let wb = 1 + (next(&mut x) % 14) as usize;
        let (a, b) = (next(&mut x) as u32, next(&mut x) as u32);
        let words: Vec<u32> = (0..sps * k)
            .map(|u| {
                let w = if round % 2 == 0 {
                    ((u % sps) as u32).wrapping_mul(a) ^ ((u / sps) as u32 & b)
                } else {
                    next(&mut x) as u32
                };
                w & ((1 << wb) - 1)
            })
            .collect();
        let l = SlotLogic::of(&words, wb, sps, k, |_| 0);
        for j in 0..k {
            for p in 0..sps {
                assert_eq!(
                    l.word(p, j),
                    words[j * sps + p],
                    "sps {sps} k {k} p {p} j {j}"
                );
            }
        }
    }
}

/// A column that is the slot in the slice is wires; one that only
/// converts in slot 0 is one small function; neither costs the ROM's
/// frame-wide pointer, while a random table does.
#[test]
fn regular_columns_cost_little_and_random_ones_much() {
    let (sps, k) = (30, 10);
    let ident: Vec<u32> = (0..sps * k).map(|u| (u % sps) as u32).collect();
    let l = SlotLogic::of(&ident, 5, sps, k, |_| 0);
    assert_eq!(SlotLogic::cost(&[&l]), 0);
    assert!(l.bits.iter().all(|f| f.vars.len() == 1), "{:?}", l.bits);
    let first: Vec<u32> = (0..sps * k)
        .map(|u| (u % sps == 0 && u / sps < 9) as u32)
        .collect();
    let l = SlotLogic::of(&first, 1, sps, k, |_| 0);
    assert!(
        (1..=4).contains(&SlotLogic::cost(&[&l])),
        "{}",
        SlotLogic::cost(&[&l])
    );
    let mut x = 7;
    let rnd: Vec<u32> = (0..sps * k).map(|_| next(&mut x) as u32 & 0xff).collect();
    let l = SlotLogic::of(&rnd, 8, sps, k, |_| 0);
    assert!(SlotLogic::cost(&[&l]) > 100, "{}", SlotLogic::cost(&[&l]));
}
