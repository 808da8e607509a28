use measure::for_tests::{label_width, stagger};

#[test]
fn strobe_labels_a_slot_apart_alternate_lines() {
    let l: Vec<(f64, String)> = (0..6).map(|k| (k as f64, "CH10".to_string())).collect();
    // 30 slots in the window: a label is wider than a slot
    let lines = |v: Vec<(f64, usize)>| v.into_iter().map(|p| p.1).collect::<Vec<_>>();
    assert_eq!(lines(stagger(&l, &[], 0.0, 30.0, 2)), [0, 1, 0, 1, 0, 1]);
    // wider labels take a third line where there is one
    let w: Vec<(f64, String)> = (0..6).map(|k| (k as f64, "CH1,CH26".into())).collect();
    assert_eq!(lines(stagger(&w, &[], 0.0, 30.0, 3)), [0, 1, 2, 0, 1, 2]);
    // far apart: all on the first line
    let far: Vec<(f64, String)> = l.iter().map(|(x, t)| (x * 10.0, t.clone())).collect();
    assert_eq!(lines(stagger(&far, &[], 0.0, 60.0, 2)), [0; 6]);
}

/// A strobe's tick under a name on the first line (which sits among
/// the ticks) sends the name to a line below the trace: eskin34's
/// merged "CH1,CH26,CH35" crossed the next two strobes' ticks.
#[test]
fn no_strobe_tick_crosses_a_name_on_the_first_line() {
    let width = label_width("CH1,CH26,CH35", 30.0);
    let ticks = [0.0, 0.0 + width / 2.0, 5.0];
    let l = vec![
        (0.0, "CH1,CH26,CH35".to_string()),
        (width / 2.0, "CH2".to_string()),
        (5.0, "CH3".to_string()),
    ];
    let placed = stagger(&l, &ticks, 0.0, 30.0, 3);
    assert_eq!(placed.iter().map(|p| p.1).collect::<Vec<_>>(), [1, 0, 0]);
    for ((x, line), (_, t)) in placed.iter().zip(&l) {
        let end = x + label_width(t, 30.0);
        let under = ticks.iter().any(|&k| k > *x + 0.21 && k < end);
        assert!(*line > 0 || !under, "{t} on line 0 over a tick");
    }
    // its own strobes' ticks, left of its text, do not count
    let alone = stagger(&l[..1], &[0.0, 0.1], 0.0, 30.0, 3);
    assert_eq!(alone[0].1, 0);
}

#[test]
fn a_label_at_the_right_edge_ends_inside_the_window() {
    let l = vec![(9.0, "CH1".to_string()), (29.9, "CH1,CH26".to_string())];
    let placed = stagger(&l, &[], 0.0, 30.0, 2);
    assert_eq!(placed[0].0, 9.0, "a label with room stays at its strobe");
    let end = placed[1].0 + label_width("CH1,CH26", 30.0);
    assert!(end <= 30.0 + 1e-9 && placed[1].0 < 29.9, "{placed:?}");
}
