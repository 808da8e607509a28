use lut_gen::for_tests::{apply, Edit};

#[test]
fn edits_keep_the_users_comments_and_change_only_what_they_name() {
    let text = "# my mix\nname = \"m\"\n[frame]\nperiod_us = 1000 # one ms\nslice_us = 500\nslots_per_slice = 4\n\
                [[branch]]\nname = \"a\"\nmux_devices = 1\n[[channel]]\nname = \"x\"\nbranch = \"a\"\ninput = 3\nrate_hz = 1000\n";
    let out = apply(
        text,
        &[
            Edit::FreeGrid,
            Edit::SliceUs(250),
            Edit::MoveChannel {
                name: "x".into(),
                to: "b".into(),
            },
            Edit::Rate {
                name: "x".into(),
                hz: 500,
            },
            Edit::MuxDevices {
                name: "a".into(),
                devices: 2,
            },
            Edit::BranchLike {
                name: "b".into(),
                like: "a".into(),
            },
        ],
    )
    .unwrap();
    assert!(out.starts_with("# my mix\n"), "{out}");
    assert!(out.contains("period_us = 1000 # one ms"), "{out}");
    assert!(!out.contains("slots_per_slice"), "{out}");
    assert!(out.contains("slice_us = 250"), "{out}");
    assert!(!out.contains("input"), "{out}");
    assert!(out.contains("rate_hz = 500"), "{out}");
    assert!(out.contains("mux_devices = 2"), "{out}");
    assert_eq!(out.matches("[[branch]]").count(), 2, "{out}");
    assert!(apply(
        text,
        &[Edit::Rate {
            name: "nobody".into(),
            hz: 1
        }]
    )
    .is_none());
}
