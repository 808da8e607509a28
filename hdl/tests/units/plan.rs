use hdl::for_tests::{logic_costs, plan_with, SlotLogic};
use hdl::LutForm;
use lut_gen::Schedule;

fn schedule(mix: &str) -> Schedule {
    let path = testkit::root().join("mixes").join(mix);
    let text = std::fs::read_to_string(&path).unwrap();
    lut_gen::synthesize(&lut_gen::parse(&path, &text).unwrap()).unwrap()
}

/// The queue form where one sequencer completes every branch's single
/// word (eskin34, whose slot 1 has branches 0 and 2 only), the
/// priority form for a chain (vibrotactile8k); in the queue form lane
/// `j`'s ROM names the channel of the slot's `j`-th converting branch.
#[test]
fn queue_form_where_one_sequencer_completes_single_words() {
    let s = schedule("eskin34.toml");
    let p = plan_with(&s, LutForm::Full).unwrap();
    let q = p.queue.as_ref().expect("eskin34: queue form");
    assert_eq!(q[1], vec![1, 2]);
    for u in 0..s.grid.frame_slots {
        let on: Vec<usize> = (0..p.branches.len()).filter_map(|b| s.at(u, b)).collect();
        for (b, rom) in p.branches.iter().enumerate() {
            let w = rom.words[u as usize];
            let conv = w >> (rom.ch_bits + 3 + rom.dev_bits) & 1 == 1;
            let ch = (w >> (3 + rom.dev_bits)) as usize & ((1 << rom.ch_bits) - 1);
            assert_eq!(conv, s.at(u, b).is_some(), "slot {u} branch {b}");
            if let Some(&c) = on.get(b) {
                assert_eq!(ch, c, "slot {u} lane {b}");
            }
        }
    }
    let v = schedule("vibrotactile8k.toml");
    assert!(plan_with(&v, LutForm::Full).unwrap().queue.is_none());
}

/// The queue form's channel table, as the merger reads it: during frame
/// slot `u` (ROM address `u + 1`), word `k` out is the slot's `k`-th
/// converting branch's channel, flagged while another follows; the
/// entries no completion reads are zero. Only with the full table.
#[test]
fn the_channel_table_names_each_slots_words_in_branch_order() {
    let s = schedule("eskin34.toml");
    let p = plan_with(&s, LutForm::Full).unwrap();
    let t = p.lane_ch.as_ref().expect("eskin34: the channel table");
    let (fs, nb) = (s.grid.frame_slots, p.branches.len());
    assert_eq!(t.words.len(), 1 << (t.addr_bits + t.k_bits));
    let mut read = vec![false; t.words.len()];
    for u in 0..fs {
        let on: Vec<usize> = (0..nb).filter_map(|b| s.at(u, b)).collect();
        let a = ((u + 1) % fs) as usize;
        for (k, &c) in on.iter().enumerate() {
            let w = t.words[(a << t.k_bits) | k];
            assert_eq!(w & ((1 << t.ch_bits) - 1), c as u32, "slot {u} word {k}");
            assert_eq!(w >> t.ch_bits == 1, k + 1 < on.len(), "slot {u} word {k}");
            read[(a << t.k_bits) | k] = true;
        }
    }
    assert!((0..t.words.len()).all(|i| read[i] || t.words[i] == 0));
    // the frame's first slot reads the table at address 1
    assert_eq!(
        t.words[1 << t.k_bits] & ((1 << t.ch_bits) - 1),
        s.at(0, 0).unwrap() as u32
    );
    for form in [LutForm::Compact, LutForm::Logic] {
        assert!(plan_with(&s, form).unwrap().lane_ch.is_none(), "{form:?}");
    }
}

/// Every preset, shared test mix and gateware test mix: where `Auto`
/// decodes slots by logic, and wherever the logic form is forced, each
/// branch's logic gives the full table's word at every slot of the
/// frame (its channel free where the branch does not convert), and
/// `Auto` took it only where the estimate says it costs less.
#[test]
fn logic_decoding_equals_the_table_and_is_chosen_by_cost() {
    let mut mixes: Vec<std::path::PathBuf> = vec![];
    for d in ["mixes", "testkit/mixes", "hdl/tests/data"] {
        let mut v: Vec<_> = std::fs::read_dir(testkit::root().join(d))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        v.sort();
        mixes.extend(v);
    }
    let (mut chosen, mut kept) = (0, 0);
    for path in &mixes {
        let text = std::fs::read_to_string(path).unwrap();
        let Ok(s) = lut_gen::synthesize(&lut_gen::parse(path, &text).unwrap()) else {
            continue;
        };
        let Ok(full) = plan_with(&s, LutForm::Full) else {
            continue;
        };
        let auto = plan_with(&s, LutForm::Auto).unwrap();
        let Ok(forced) = plan_with(&s, LutForm::Logic) else {
            assert!(full.modes.is_some() || full.branches.iter().any(|r| r.command.is_some()));
            assert!(!auto.logic);
            continue;
        };
        let logic: Vec<SlotLogic> = forced
            .branches
            .iter()
            .map(|r| r.logic.clone().unwrap())
            .collect();
        let (rom, counters, decode) = logic_costs(&full, &logic);
        assert_eq!(auto.logic, counters + decode < rom, "{}", path.display());
        if auto.logic {
            chosen += 1;
        } else {
            kept += 1;
        }
        let sps = s.grid.slots_per_slice as usize;
        for (b, r) in full.branches.iter().enumerate() {
            let l = &logic[b];
            for u in 0..s.grid.frame_slots as usize {
                let (w, d) = (r.words[u], l.word(u % sps, u / sps));
                let care = !r.free_bits(u);
                assert_eq!(d & care, w & care, "{} branch {b} slot {u}", path.display());
            }
        }
    }
    // the presets have both kinds
    assert!(chosen >= 3 && kept >= 2, "{chosen} {kept}");
}
