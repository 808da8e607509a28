use lut_gen::{io_words, write_words};
use std::io::Error;

#[test]
fn os_errors_are_words_without_numbers() {
    let missing = std::fs::read("/no/such/slotforge/file").unwrap_err();
    assert_eq!(io_words(&missing), "no such file");
    assert_eq!(write_words(&missing), "no such folder");
    let dir = std::fs::read_to_string(env!("CARGO_MANIFEST_DIR")).unwrap_err();
    assert_eq!(io_words(&dir), "is a folder, not a file");
    let other = Error::from_raw_os_error(28);
    let w = io_words(&other);
    assert!(!w.contains("os error") && w.starts_with("no space"), "{w}");
}
