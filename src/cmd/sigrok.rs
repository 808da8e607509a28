//! `slotforge sigrok MIX -o DIR`: a sigrok protocol decoder for the mix's
//! packets (`DIR/<id>/__init__.py`, `pd.py`; `<id>` is `slotforge_` and
//! the mix's name), stacked on sigrok's `uart` decoder, for PulseView and
//! sigrok-cli (`SIGROKDECODE_DIR=DIR`).  The decoder's text is
//! `host::sigrok_decoder`'s.

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML) with a UART `[link]`.
    pub mix: PathBuf,
    /// The folder of decoders to write into (created if missing); the
    /// decoder goes in its own subfolder, named by its id.
    #[arg(short, long)]
    pub out: PathBuf,
}

pub fn run(a: Args) -> u8 {
    let s = match super::schedule(&a.mix) {
        Ok(s) => s,
        Err(code) => return code,
    };
    // a link too slow for the mix: refused as every command refuses it (exit 1)
    if let Err(code) = super::link_fits(&s, &a.mix) {
        return code;
    }
    let pd = match host::sigrok_decoder(&s) {
        Ok(pd) => pd,
        Err(e) => {
            eprintln!("error: {}: {e}", a.mix.display());
            return 2;
        }
    };
    let dir = a.out.join(&pd.id);
    if let Err(code) = super::write_files(&dir, &pd.files) {
        return code;
    }
    println!("wrote {}: decoder `{}`", dir.display(), pd.id);
    println!(
        "  SIGROKDECODE_DIR={} sigrok-cli -i CAPTURE -P uart:rx=LINE:{},{} -A {}",
        a.out.display(),
        pd.uart_options,
        pd.id,
        pd.id
    );
    0
}
