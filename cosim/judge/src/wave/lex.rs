//! The VCD body, lexed in parallel: the file is read in bounded chunks cut
//! at line ends, worker threads turn each chunk into a compact list of
//! events (timestamps, and value changes already resolved to the ports they
//! feed and parsed), and the caller applies the lists in file order.  The
//! lexer was most of `check`'s time (`docs/performance.md`); the judge stays
//! on one thread because a cycle's verdict depends on every earlier cycle.
//!
//! Memory stays flat in the file size: at most [`IN_FLIGHT`] chunks (text
//! plus events) exist at once.  A chunk is lexed from a clean state (not
//! inside a `$comment`, not between a vector value and its identifier
//! code); one that ends in such a state is not applied but joined to the
//! next chunk and lexed again, so a cut at any line end gives the same
//! events and the same errors as reading the file in one piece.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;
use std::sync::mpsc;
use std::sync::{Arc, Mutex};

use crate::wave::read::{parse_value, Ids, Val, VcdError};

/// Bytes of text per chunk (about 2 ms of lexing: thread hand-offs cost
/// nothing beside it, and the chunks in flight stay a few MB).
const CHUNK: usize = 1 << 18;
/// Chunks being read, lexed or waiting to be applied, at most.
const IN_FLIGHT: usize = 8;

thread_local! {
    /// The chunk size, smaller in unit tests so that small files are cut.
    static CHUNK_BYTES: std::cell::Cell<usize> = const { std::cell::Cell::new(CHUNK) };
}

/// Sets this thread's chunk size (tests only, through `for_tests`: cuts
/// everywhere).
pub fn set_chunk_bytes(n: usize) {
    CHUNK_BYTES.with(|c| c.set(n.max(1)));
}

/// One event of the body, in file order.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Ev {
    /// `#t` on the chunk's line `line` (0-based).
    Time { t: u64, line: u32 },
    /// A change of the flat sink `sink` (value and x/z mask, masked to the
    /// sink's width) that fits in 32 bits (16 bytes an event).
    Set { sink: u32, v: u32, x: u32 },
    /// The same, wider: the value is `Lexed::wide[idx]`.
    Wide { sink: u32, idx: u32 },
}

/// How a chunk ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    Clean,
    /// Inside a `$comment`.
    InComment,
    /// After a vector value, before its identifier code.
    Dangling,
}

/// A lexing error: its 0-based line in the chunk, and the message.
#[derive(Debug, Clone)]
pub(crate) struct LexError {
    pub line: u64,
    pub message: String,
}

/// One chunk, lexed.
pub(crate) struct Lexed {
    pub evs: Vec<Ev>,
    pub wide: Vec<Val>,
    /// Lines in the chunk (newlines).
    pub lines: u64,
    end: End,
    /// The first error (events before it are valid).
    pub err: Option<LexError>,
    /// The chunk's text (joined to the next chunk when it ends unclean).
    text: Vec<u8>,
}

#[inline]
fn ws(c: u8) -> bool {
    c.is_ascii_whitespace()
}

/// Lexes `text` (starting in a clean state) into events.
fn lex(text: Vec<u8>, ids: &Ids) -> Lexed {
    let mut out = Lexed {
        evs: Vec::with_capacity(text.len() / 6),
        wide: Vec::new(),
        lines: 0,
        end: End::Clean,
        err: None,
        text: Vec::new(),
    };
    let mut cur = Cursor {
        b: &text,
        i: 0,
        line: 0,
    };
    while let Some((s, e)) = cur.next() {
        let t = &text[s..e];
        let r = match t[0] {
            b'#' => time(&mut out, t, cur.line),
            b'$' => skip_comment(&mut cur, t),
            b'b' | b'B' | b'r' | b'R' | b's' | b'S' => vector(&mut out, &mut cur, t, ids),
            _ => scalar(&mut out, t, ids),
        };
        match r {
            Ok(()) => {}
            Err(Stop::Error(message)) => {
                out.err = Some(LexError {
                    line: cur.line,
                    message,
                });
                break;
            }
            Err(Stop::End(end)) => {
                out.end = end;
                break;
            }
        }
    }
    out.lines = cur.line + text[cur.i..].iter().filter(|&&c| c == b'\n').count() as u64;
    out.text = text;
    out
}

/// Why lexing a chunk stopped before its end.
enum Stop {
    /// A syntax error (on the cursor's line).
    Error(String),
    /// The chunk ends in a state that is not clean.
    End(End),
}

/// The position in a chunk's text, counting lines.
struct Cursor<'a> {
    b: &'a [u8],
    i: usize,
    line: u64,
}

impl Cursor<'_> {
    /// The next token as [s, e).
    #[inline]
    fn next(&mut self) -> Option<(usize, usize)> {
        let (b, n) = (self.b, self.b.len());
        while self.i < n && ws(b[self.i]) {
            if b[self.i] == b'\n' {
                self.line += 1;
            }
            self.i += 1;
        }
        if self.i == n {
            return None;
        }
        let s = self.i;
        while self.i < n && !ws(b[self.i]) {
            self.i += 1;
        }
        Some((s, self.i))
    }
}

fn lossy(r: &[u8]) -> String {
    String::from_utf8_lossy(r).into_owned()
}

/// `#t`: a timestamp.
#[inline]
fn time(out: &mut Lexed, t: &[u8], line: u64) -> Result<(), Stop> {
    let Some(nt) = timestamp(&t[1..]) else {
        return Err(Stop::Error(format!("bad timestamp `{}`", lossy(t))));
    };
    out.evs.push(Ev::Time {
        t: nt,
        line: line as u32,
    });
    Ok(())
}

/// A `$` keyword: a `$comment` is skipped to its `$end`, others ignored.
fn skip_comment(cur: &mut Cursor, t: &[u8]) -> Result<(), Stop> {
    if t != b"$comment" {
        return Ok(());
    }
    loop {
        match cur.next() {
            None => return Err(Stop::End(End::InComment)),
            Some((s, e)) if &cur.b[s..e] == b"$end" => return Ok(()),
            Some(_) => {}
        }
    }
}

/// A vector (or real, or string) value `t` and, next, its identifier code:
/// vectors are parsed for the sinks the code feeds; others are skipped.
#[inline]
fn vector(out: &mut Lexed, cur: &mut Cursor, t: &[u8], ids: &Ids) -> Result<(), Stop> {
    let is_b = t[0] == b'b' || t[0] == b'B';
    let val = &t[1..];
    let Some((is, ie)) = cur.next() else {
        return Err(Stop::End(End::Dangling));
    };
    let id = &cur.b[is..ie];
    let Some(span) = ids.span(id) else {
        return Err(Stop::Error(format!(
            "value change for undeclared identifier code `{}`",
            lossy(id)
        )));
    };
    if is_b && !span.is_empty() {
        for k in span {
            let sink = ids.flat[k];
            let Some(v) = parse_value(val, sink.width) else {
                return Err(Stop::Error(format!("bad vector value `b{}`", lossy(val))));
            };
            push(out, k as u32, v, sink.width);
        }
    } else if is_b && parse_value(val, 1).is_none() && val.len() <= 64 {
        return Err(Stop::Error(format!("bad vector value `b{}`", lossy(val))));
    }
    Ok(())
}

/// A scalar value change `t`: its value character, then its identifier code.
#[inline]
fn scalar(out: &mut Lexed, t: &[u8], ids: &Ids) -> Result<(), Stop> {
    if !matches!(
        t[0],
        b'0' | b'1'
            | b'x'
            | b'X'
            | b'z'
            | b'Z'
            | b'u'
            | b'U'
            | b'w'
            | b'W'
            | b'l'
            | b'L'
            | b'h'
            | b'H'
            | b'-'
    ) {
        return Err(Stop::Error(format!("unexpected `{}`", lossy(t))));
    }
    if t.len() < 2 {
        return Err(Stop::Error(
            "scalar value change without an identifier code".into(),
        ));
    }
    let Some(span) = ids.span(&t[1..]) else {
        return Err(Stop::Error(format!(
            "value change for undeclared identifier code `{}`",
            lossy(&t[1..])
        )));
    };
    if !span.is_empty() {
        // The scalar's one character, checked above (what `parse_value`
        // gives for it, without its loop).
        let v = match t[0] {
            b'0' | b'l' | b'L' => Val { v: 0, x: 0 },
            b'1' | b'h' | b'H' => Val { v: 1, x: 0 },
            _ => Val { v: 0, x: 1 },
        };
        for k in span {
            let sink = ids.flat[k];
            let v = Val {
                v: v.v,
                x: if v.x != 0 { u128::MAX } else { 0 },
            };
            push(out, k as u32, v, sink.width);
        }
    }
    Ok(())
}

/// A timestamp's digits as `u64`: plain digits directly (most of a body's
/// tokens), anything else as `str::parse` reads it, so what is accepted and
/// refused does not change.
#[inline]
fn timestamp(d: &[u8]) -> Option<u64> {
    if !d.is_empty() && d.len() <= 19 && d.iter().all(u8::is_ascii_digit) {
        return Some(d.iter().fold(0u64, |n, &c| n * 10 + (c - b'0') as u64));
    }
    std::str::from_utf8(d).ok()?.parse::<u64>().ok()
}

#[inline]
fn push(out: &mut Lexed, sink: u32, v: Val, width: u32) {
    let m = if width >= 128 {
        u128::MAX
    } else {
        (1u128 << width) - 1
    };
    let (v, x) = (v.v & m, v.x & m);
    if (v | x) >> 32 == 0 {
        out.evs.push(Ev::Set {
            sink,
            v: v as u32,
            x: x as u32,
        });
    } else {
        out.evs.push(Ev::Wide {
            sink,
            idx: out.wide.len() as u32,
        });
        out.wide.push(Val { v, x });
    }
}

/// Where the body starts: byte offset and the 1-based line number there.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BodyStart {
    pub offset: u64,
    pub line: u64,
    /// Whether the header's last line ended with a newline (for a file
    /// whose body is empty).
    pub header_newline: bool,
}

/// What the applier is told with every chunk.
pub(crate) struct At {
    /// 1-based line number of the chunk's first line.
    pub line0: u64,
}

/// Reads the body of `path` from `start`, lexes it on worker threads, and
/// hands each chunk's events to `apply` in file order.  A lexing error of a
/// chunk comes after its valid events were applied, as `VcdError` with the
/// file's line.  Returns the line of the file's last character and whether
/// the file ends with a newline.  `read` is told the bytes of the body
/// applied so far after every chunk (a progress display).
pub(crate) fn for_each_chunk(
    path: &Path,
    start: BodyStart,
    ids: &Ids,
    read: &dyn Fn(u64),
    mut apply: impl FnMut(&Lexed, &At) -> Result<(), VcdError>,
) -> Result<(u64, bool), VcdError> {
    let io = |e| VcdError::Io(path.to_path_buf(), e);
    let mut f = File::open(path).map_err(io)?;
    f.seek(SeekFrom::Start(start.offset)).map_err(io)?;
    std::thread::scope(|scope| {
        let mut queue = spawn_lexers(scope, ids);
        let mut reader = Chunker {
            size: CHUNK_BYTES.with(|c| c.get()),
            f: &mut f,
            rest: Vec::new(),
            eof: false,
        };
        let mut line0 = start.line;
        // Text of unclean chunks, to be lexed again with what follows.
        let mut carry: Vec<u8> = Vec::new();
        let mut last = (start.line, start.header_newline);
        let mut applied = 0u64;
        loop {
            queue.fill(&mut reader).map_err(io)?;
            let Some(mut lexed) = queue.take() else {
                break;
            };
            let is_last = queue.next == queue.sent && reader.eof;
            if !carry.is_empty() {
                carry.extend_from_slice(&lexed.text);
                lexed = lex(std::mem::take(&mut carry), ids);
            }
            if lexed.end != End::Clean && !is_last && lexed.err.is_none() {
                carry = std::mem::take(&mut lexed.text);
                continue;
            }
            let at = At { line0 };
            let last_line = line0 + lexed.lines;
            let incomplete = is_last && lexed.text.last().is_some_and(|&c| c != b'\n');
            apply(&lexed, &at).map_err(|e| truncation(e, incomplete, last_line))?;
            if let Some(e) = lexed.err.take() {
                let e = VcdError::Malformed {
                    file: path.to_path_buf(),
                    line: line0 + e.line,
                    message: e.message,
                };
                return Err(truncation(e, incomplete, last_line));
            }
            let text = &lexed.text;
            applied += text.len() as u64;
            read(applied);
            if let Some(&c) = text.last() {
                let trailing = (c == b'\n') as u64;
                last = (line0 + lexed.lines - trailing, c == b'\n');
            }
            if lexed.end != End::Clean {
                return Err(unclean_end(path, lexed.end, last.0));
            }
            line0 += lexed.lines;
        }
        Ok(last)
    })
}

/// The file ends inside a `$comment` or after a vector value.
fn unclean_end(path: &Path, end: End, line: u64) -> VcdError {
    let message = match end {
        End::InComment => "end of file inside $comment",
        _ => "value change without an identifier code at the end of the file",
    };
    VcdError::Truncated {
        file: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Chunks handed to the lexer threads, and taken back in file order.
struct LexQueue {
    work_tx: mpsc::Sender<(u64, Vec<u8>)>,
    done_rx: mpsc::Receiver<(u64, Lexed)>,
    /// Chunks sent, and the next to take back (in file order).
    sent: u64,
    next: u64,
    /// Lexed chunks come back in any order: each waits in its slot.
    waiting: Vec<Option<Lexed>>,
}

/// Starts the lexer threads (at most four).
fn spawn_lexers<'scope>(
    scope: &'scope std::thread::Scope<'scope, '_>,
    ids: &'scope Ids,
) -> LexQueue {
    let workers = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .clamp(1, 4);
    let (work_tx, work_rx) = mpsc::channel::<(u64, Vec<u8>)>();
    let work_rx = Arc::new(Mutex::new(work_rx));
    let (done_tx, done_rx) = mpsc::channel::<(u64, Lexed)>();
    for _ in 0..workers {
        let rx = Arc::clone(&work_rx);
        let tx = done_tx.clone();
        scope.spawn(move || loop {
            let job = rx.lock().expect("a lexer thread panicked").recv();
            let Ok((seq, text)) = job else { return };
            if tx.send((seq, lex(text, ids))).is_err() {
                return;
            }
        });
    }
    LexQueue {
        work_tx,
        done_rx,
        sent: 0,
        next: 0,
        waiting: Vec::new(),
    }
}

impl LexQueue {
    /// Sends chunks until [`IN_FLIGHT`] are out or the file is read.
    fn fill(&mut self, reader: &mut Chunker) -> std::io::Result<()> {
        while self.sent - self.next < IN_FLIGHT as u64 && !reader.eof {
            let text = reader.chunk()?;
            if text.is_empty() {
                break;
            }
            self.work_tx
                .send((self.sent, text))
                .expect("lexer threads alive");
            self.sent += 1;
        }
        Ok(())
    }

    /// The next chunk in file order, once lexed (`None`: all taken).
    fn take(&mut self) -> Option<Lexed> {
        if self.next == self.sent {
            return None;
        }
        let slot = (self.next % IN_FLIGHT as u64) as usize;
        if self.waiting.len() < IN_FLIGHT {
            self.waiting.resize_with(IN_FLIGHT, || None);
        }
        while self.waiting[slot].is_none() {
            let (seq, lexed) = self.done_rx.recv().expect("lexer threads alive");
            self.waiting[(seq % IN_FLIGHT as u64) as usize] = Some(lexed);
        }
        self.next += 1;
        Some(self.waiting[slot].take().expect("just received"))
    }
}

/// A syntax error on the file's incomplete last line is a truncation.
fn truncation(e: VcdError, incomplete: bool, last_line: u64) -> VcdError {
    match e {
        VcdError::Malformed {
            file,
            line,
            message,
        } if incomplete && line == last_line => VcdError::Truncated {
            file,
            line,
            message: format!("{message} (the last line is incomplete)"),
        },
        e => e,
    }
}

/// Reads the file in chunks of about [`CHUNK`] bytes, each ending at a line
/// end (or the file's end).
struct Chunker<'a> {
    size: usize,
    f: &'a mut File,
    /// Text after the last cut.
    rest: Vec<u8>,
    eof: bool,
}

impl Chunker<'_> {
    fn chunk(&mut self) -> std::io::Result<Vec<u8>> {
        let mut buf = std::mem::take(&mut self.rest);
        loop {
            let have = buf.len();
            buf.resize(have + self.size, 0);
            let mut got = have;
            while got < buf.len() {
                match self.f.read(&mut buf[got..]) {
                    Ok(0) => {
                        self.eof = true;
                        break;
                    }
                    Ok(k) => got += k,
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                    Err(e) => return Err(e),
                }
            }
            buf.truncate(got);
            if self.eof {
                return Ok(buf);
            }
            // Cut after the last newline; a chunk with none grows.
            if let Some(p) = buf.iter().rposition(|&c| c == b'\n') {
                self.rest = buf[p + 1..].to_vec();
                buf.truncate(p + 1);
                return Ok(buf);
            }
        }
    }
}
