//! What the operating system says about a file, in the user's words: "no
//! such file" rather than "No such file or directory (os error 2)". Every
//! place that opens a path the user gave (the mix, `--rtl`, `--samples`,
//! `--map`, a capture, a board file) words its error with [`io_words`].

use std::io::{Error, ErrorKind};

/// [`io_words`] for a file being written: a missing path there is a
/// missing folder.
pub fn write_words(e: &Error) -> String {
    match e.kind() {
        ErrorKind::NotFound => "no such folder".into(),
        _ => io_words(e),
    }
}

/// `e` as a short phrase in words, without the OS's error number.
pub fn io_words(e: &Error) -> String {
    // Raw numbers where `ErrorKind` has no stable variant yet (Rust 1.80).
    const ENOTDIR: i32 = 20;
    const EISDIR: i32 = 21;
    match (e.kind(), e.raw_os_error()) {
        (ErrorKind::NotFound, _) => "no such file".into(),
        (ErrorKind::PermissionDenied, _) => "permission denied".into(),
        (_, Some(EISDIR)) => "is a folder, not a file".into(),
        (_, Some(ENOTDIR)) => "a part of the path is a file, not a folder".into(),
        _ => {
            // Any other OS text, its "(os error N)" tail dropped.
            let text = e.to_string();
            let text = match text.rfind(" (os error ") {
                Some(i) => text[..i].to_string(),
                None => text,
            };
            let mut c = text.chars();
            match c.next() {
                Some(f) => f.to_lowercase().chain(c).collect(),
                None => text,
            }
        }
    }
}
