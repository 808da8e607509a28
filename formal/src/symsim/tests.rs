use super::*;
use crate::aiger::parse;

/// A 2-bit counter (period 4) with a shift register of the input; the
/// assertion: the register's bit 1 equals the input of two steps ago,
/// which a second register records.
fn counter_and_shift(bug: bool) -> Aig {
    // inputs: 2 (x); latches: 4 c0, 6 c1, 8 s0, 10 s1, 12 r0, 14 r1
    // c0' = !c0; c1' = c1 ^ c0; s0' = x; s1' = s0; r0' = x; r1' = r0 (or !r0 if bug at c = 3)
    // bad = s1 ^ r1
    let mut t = String::new();
    let ands: Vec<(u32, u32, u32)> = vec![
        (16, 6, 5),   // c1 & !c0
        (18, 7, 4),   // !c1 & c0
        (20, 11, 14), // !s1 & r1
        (22, 10, 15), // s1 & !r1
        (24, 4, 6),   // c0 & c1 (count 3)
        (26, 25, 12), // !(c0&c1) & r0
        (28, 24, 13), // c0&c1 & !r0
    ];
    // c1' = (c1&!c0) | (!c1&c0) = !( !16 & !18 )
    let mut all = ands.clone();
    all.push((30, 17, 19)); // !16 & !18 -> c1' = 31
    all.push((32, 21, 23)); // !20 & !22 -> bad = 33
    all.push((34, 27, 29)); // !26 & !28 -> r1' (bug) = 35
    let r1_next = if bug { 35 } else { 12 };
    t.push_str(&format!("aag 17 1 6 0 {} 1\n2\n", all.len()));
    for (l, n) in [(4, 5), (6, 31), (8, 2), (10, 8), (12, 2), (14, r1_next)] {
        t.push_str(&format!("{l} {n} 0\n"));
    }
    t.push_str("33\n");
    for (l, x, y) in all {
        t.push_str(&format!("{l} {x} {y}\n"));
    }
    parse(&t).unwrap()
}

#[test]
fn a_forgetting_design_proves_at_its_recurrence() {
    let (f, st) = run(&counter_and_shift(false), 4, 2, 100, None);
    assert_eq!(
        f,
        Found::Proved {
            steps: 10,
            since: 6,
        }
    );
    assert_eq!(st.sat_calls, 0, "the equal bits fold to a constant");
}

#[test]
fn a_fault_under_one_input_is_found_with_its_witness() {
    let g = counter_and_shift(true);
    let (f, _) = run(&g, 4, 2, 100, None);
    let Found::Violated { step, inputs } = f else {
        panic!("{f:?}")
    };
    // r1 takes !r0 when the counter is 3 (steps 3, 7, ...); s1 and r1
    // then differ at the next step whatever the input: the witness
    // replays to a failure at that step
    assert_eq!(step, 4);
    assert_eq!(inputs.len(), 5);
}

#[test]
fn a_state_that_comes_round_after_several_periods_proves_there() {
    // one latch toggled every step has period 2; compared every 3
    // steps from step 2, it differs at 5 and equals step 2's at 8
    let g = parse("aag 1 0 1 0 0 0\n2 3 0\n").unwrap();
    let (f, st) = run(&g, 3, 2, 50, None);
    assert_eq!(f, Found::Proved { steps: 8, since: 2 });
    assert_eq!(st.kept, vec![0], "the latch that changed over a period");
    let (f, _) = run(&g, 3, 2, 8, None);
    assert_eq!(
        f,
        Found::Bounded { steps: 8 },
        "no claim before the recurrence"
    );
}

#[test]
fn collection_keeps_the_state() {
    let mut gr = Graph::new();
    let x = gr.var(0, 1);
    let y = gr.var(1, 1);
    let _dead = gr.and(x, y ^ 1);
    let z = gr.and(x, y);
    let mut roots = vec![z ^ 1, x];
    let before = gr.canonical(&roots, 5);
    gr.collect(&mut roots);
    assert_eq!(gr.a.len(), 4);
    assert_eq!(gr.canonical(&roots, 5), before);
}

/// A slave's choice (input 0) shifted through `n` latches; violated when
/// the last two hold 1 (the choice was 1 twice in a row, `n` steps ago).
fn choice_shift(n: u32) -> Aig {
    choice_shift_with_tail(n, 0)
}

/// The searches of [`choice_shift`]: frames of 4 steps from step 2, 100 steps.
const SHIFT_LIMITS: Limits = Limits {
    period: 4,
    offset: 2,
    max_steps: 100,
    deadline: None,
};

#[test]
fn an_explicit_search_finds_a_deep_violation_and_its_witness_crosses_marks() {
    // 10 steps: marks every 3 in the unit tests, so the witness is
    // rebuilt from kept sets; a wrong stretch would not replay
    let g = choice_shift(10);
    let Some(Found::Violated { step, inputs }) = explicit::run(&g, &[0], &[], &SHIFT_LIMITS) else {
        panic!("no violation found");
    };
    assert_eq!(step, 10);
    // the choice was 1 at the two steps the last latches hold
    let ones: Vec<usize> = (0..inputs.len()).filter(|&s| inputs[s][0]).collect();
    assert_eq!(ones, vec![0, 1], "{inputs:?}");
}

/// [`choice_shift`] whose first latch takes the choice AND input 1, which
/// is not a choice (as yosys's `anyseq` bits are not): only that gate and
/// the latch after it may be unknown, and the search enumerates input 1
/// in the steps whose successor reads it.
fn choice_and_other_shift(n: u32) -> Aig {
    let latch = |k: u32| 6 + 2 * k;
    let (first, gate) = (latch(n), latch(n) + 2);
    let mut t = format!("aag {} 2 {n} 0 2 1\n2\n4\n", gate / 2);
    for k in 0..n {
        let next = if k == 0 { first } else { latch(k - 1) };
        t.push_str(&format!("{} {next} 0\n", latch(k)));
    }
    t.push_str(&format!(
        "{gate}\n{first} 2 4\n{gate} {} {}\n",
        latch(n - 1),
        latch(n - 2)
    ));
    parse(&t).unwrap()
}

#[test]
fn an_explicit_search_enumerates_an_input_that_is_not_a_choice_where_a_step_reads_it() {
    // the violation needs input 1 high with the choice, twice in a row:
    // evaluated as unknown it would be missed (no verdict) or, taken as 0,
    // a wrong proof
    let g = choice_and_other_shift(6);
    let Some(Found::Violated { step, inputs }) = explicit::run(&g, &[0], &[], &SHIFT_LIMITS) else {
        panic!("no violation found");
    };
    assert_eq!(step, 6);
    for (i, what) in [(0, "the choice"), (1, "input 1")] {
        let ones: Vec<usize> = (0..inputs.len()).filter(|&s| inputs[s][i]).collect();
        assert_eq!(ones, vec![0, 1], "{what}: {inputs:?}");
    }
}

#[test]
fn an_explicit_search_past_its_bound_hands_the_part_to_simulation() {
    // the set doubles every step: past 65,536 states the search gives no
    // verdict, and the symbolic run finds the violation
    let g = choice_shift(20);
    assert_eq!(explicit::run(&g, &[0], &[], &SHIFT_LIMITS), None);
    let Limits {
        period,
        offset,
        max_steps,
        ..
    } = SHIFT_LIMITS;
    let (f, st) = prove(&g, &[0], &[], &[], false, period, offset, max_steps, None);
    assert!(matches!(f, Found::Violated { step: 20, .. }), "{f:?}");
    assert_eq!(st.parts, [1, 0, 0], "simulated, not enumerated");
}

/// [`choice_shift`] with `tail` more latches after the last, which nothing
/// reads (as a slave's wait count is read by its `tready` alone): the
/// latches of the count in [`an_explicit_search_bounds_the_set_its_states_stand_for`].
fn choice_shift_with_tail(n: u32, tail: u32) -> Aig {
    let latch = |k: u32| 4 + 2 * k;
    let gate = latch(n + tail);
    let mut t = format!("aag {} 1 {} 0 1 1\n2\n", gate / 2, n + tail);
    for k in 0..n + tail {
        let next = if k == 0 { 2 } else { latch(k - 1) };
        t.push_str(&format!("{} {next} 0\n", latch(k)));
    }
    t.push_str(&format!(
        "{gate}\n{gate} {} {}\n",
        latch(n - 1),
        latch(n - 2)
    ));
    parse(&t).unwrap()
}

/// With a wait count the bound is on the set as it may be without
/// subsumption (a state stands for up to 2^bits), so a cone that reads the
/// data gives up no later than before, not crawls to the deadline (an auto
/// AXI4-Stream gateware that ignores `tready` was bounded, not refuted,
/// while its subsumed set was held to the plain bound).
#[test]
fn an_explicit_search_bounds_the_set_its_states_stand_for() {
    // 14 latches and a 3-latch count: 2^14 states at step 14 stand for up
    // to 2^17, past 65,536; without the count they fit, and the search
    // finds the violation
    let g = choice_shift_with_tail(14, 3);
    assert_eq!(explicit::run(&g, &[0], &[14, 15, 16], &SHIFT_LIMITS), None);
    let f = explicit::run(&g, &[0], &[], &SHIFT_LIMITS);
    assert!(matches!(f, Some(Found::Violated { step: 14, .. })), "{f:?}");
    // a smaller set is searched with the count as without it
    let g = choice_shift_with_tail(8, 3);
    let (a, b) = (
        explicit::run(&g, &[0], &[8, 9, 10], &SHIFT_LIMITS),
        explicit::run(&g, &[0], &[], &SHIFT_LIMITS),
    );
    assert!(matches!(a, Some(Found::Violated { step: 8, .. })), "{a:?}");
    assert!(matches!(b, Some(Found::Violated { step: 8, .. })), "{b:?}");
}

/// A 3-bit counter that counts the steps in which all `n` choice inputs
/// are high; the assertion: it never reaches 7 (it does, after 7 such
/// steps). Not 2-inductive (6 counts on to 7), so a part for the explicit
/// search when it can enumerate `n` choice bits.
fn all_choices_counter(n: u32) -> Aig {
    let mut ands: Vec<(u32, u32, u32)> = Vec::new();
    let mut v = n + 4; // inputs 1..=n, latches n+1..=n+3
    let mut and = |x: u32, y: u32, ands: &mut Vec<(u32, u32, u32)>| {
        ands.push((2 * v, x, y));
        v += 1;
        2 * (v - 1)
    };
    let mut inc = 2;
    for i in 2..=n {
        inc = and(inc, 2 * i, &mut ands);
    }
    let c: Vec<u32> = (1..=3).map(|k| 2 * (n + k)).collect();
    let mut next = Vec::new();
    let mut carry = inc;
    for &ck in &c {
        // ck ^ carry, then the carry on
        let a = and(ck, carry ^ 1, &mut ands);
        let b = and(ck ^ 1, carry, &mut ands);
        next.push(and(a ^ 1, b ^ 1, &mut ands) ^ 1);
        carry = and(ck, carry, &mut ands);
    }
    let b1 = and(c[0], c[1], &mut ands);
    let bad = and(b1, c[2], &mut ands);
    let mut t = format!("aag {} {n} 3 0 {} 1\n", v - 1, ands.len());
    for i in 1..=n {
        t.push_str(&format!("{}\n", 2 * i));
    }
    for (ck, nx) in c.iter().zip(&next) {
        t.push_str(&format!("{ck} {nx} 0\n"));
    }
    t.push_str(&format!("{bad}\n"));
    for (l, x, y) in ands {
        t.push_str(&format!("{l} {x} {y}\n"));
    }
    parse(&t).unwrap()
}

#[test]
fn a_part_with_too_many_choice_bits_to_enumerate_is_simulated_instead() {
    // 6 choice bits: the explicit search; 7: the symbolic simulation
    // (its limit), and both find the count of 7 at the same step
    let mut steps = Vec::new();
    for (n, parts) in [(6, [0, 0, 1]), (7, [1, 0, 0])] {
        let g = all_choices_counter(n);
        let choices: Vec<usize> = (0..n as usize).collect();
        let (f, st) = prove(&g, &choices, &[], &[], false, 4, 2, 40, None);
        let Found::Violated { step, .. } = f else {
            panic!("{n} choice bits: {f:?}")
        };
        assert_eq!(st.parts, parts, "{n} choice bits");
        steps.push(step);
    }
    assert_eq!(steps[0], steps[1], "{steps:?}");
}

/// Input 1 copied into latch `h` every step (a request held, `defer.rs`)
/// while latch `p` is input 0 AND its value a step before (kept in `q`):
/// the run splits on input 0 in most steps, every path holding the step's
/// input 1.  Held as one variable node per (input, step), paths that meet
/// merge and the run proves at its first recurrence; held as a node of each
/// path's own, they never met and the run stopped at its bound of paths
/// (bounded at step 14).
#[test]
fn paths_that_hold_the_same_request_merge() {
    // inputs 1, 2; latches q = 3 (input 0), p = 4 (AND 6), h = 5 (input 1)
    let g = parse("aag 6 2 3 0 1 1\n2\n4\n6 2\n8 12\n10 4\n0\n12 2 6\n").unwrap();
    let lim = Limits {
        period: 16,
        offset: 2,
        max_steps: 100,
        deadline: None,
    };
    let (f, st) = Sim::split_on(&g, &[0, 1]).run(&lim);
    assert!(matches!(f, Found::Proved { steps: 18, .. }), "{f:?} {st:?}");
    assert!(st.merged > 0, "{st:?}");
}
