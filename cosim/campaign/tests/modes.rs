//! The fault campaign on mixes with modes (docs/faults.md, "Mode
//! switches"): every run switches (pin select: a request; auto: a touch),
//! the `mode` output's faults join the classes at the frame starts of the
//! switch, and every class is caught on the model back end, the mode
//! faults by the model and by the invariants (sigrok cannot see `mode`).

use campaign::{campaign_with, Detector, Plan, Target};

fn schedule(name: &str) -> lut_gen::Schedule {
    let path = testkit::mix(name);
    lut_gen::synthesize(&lut_gen::load(&path).unwrap()).unwrap()
}

#[test]
fn mode_faults_join_the_campaign_and_are_caught() {
    for name in ["modes-pin", "modes-auto"] {
        let s = schedule(name);
        let mut plan = Plan::new(Target::Model, 4, 0);
        plan.sigrok = false;
        let c = campaign_with(&s, &plan).unwrap();
        for class in ["mode-early", "mode-stuck", "mode-unasked"] {
            let o = c
                .classes
                .iter()
                .find(|o| o.name.name() == class)
                .unwrap_or_else(|| panic!("{name}: no {class} injected"));
            assert_eq!(o.injected, 1, "{name} {class}");
            for d in [Detector::Model, Detector::Invariants] {
                assert_eq!(o.detected_by.get(&d), Some(&1), "{name} {class}: {d:?}");
            }
            assert!(
                o.cannot_see.contains_key(&Detector::Sigrok),
                "{name} {class}"
            );
        }
        // every class of the switching run is caught, none rejected clean
        assert!(
            c.ok(),
            "{name}: {:?}",
            c.classes
                .iter()
                .filter(|o| !o.undetected.is_empty())
                .map(|o| o.name.name())
                .collect::<Vec<_>>()
        );
        // a mix without modes has none
        let plain = schedule("tiny");
        assert!(!judge::PinFault::all(&plain).iter().any(|f| f.is_mode()));
    }
}
