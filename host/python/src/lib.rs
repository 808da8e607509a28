//! `slotforge._native`: the `host` crate's decoder for Python.  The
//! package around it (`python/slotforge/`) turns its columns into numpy
//! arrays; every byte's meaning and every sampling instant is the Rust
//! decoder's, the same one `slotforge decode` runs.

use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

/// A mix file, loaded and scheduled.
#[pyclass(module = "slotforge._native", frozen)]
struct Mix {
    s: lut_gen::Schedule,
}

#[pymethods]
impl Mix {
    /// Loads and schedules the mix at `path`; a bad mix raises ValueError
    /// with the file, line and field.
    #[new]
    fn new(path: PathBuf) -> PyResult<Mix> {
        let mix = lut_gen::load(&path).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let s = lut_gen::synthesize(&mix).map_err(|e| {
            let msg = format!("{}: {}: {e}", path.display(), e.verdict.as_str());
            PyValueError::new_err(msg.trim_end().to_string())
        })?;
        Ok(Mix { s })
    }

    #[getter]
    fn name(&self) -> String {
        self.s.mix.name.clone()
    }

    /// The channels' names in the mix's order.
    #[getter]
    fn channels(&self) -> Vec<String> {
        self.s.mix.channels.iter().map(|c| c.name.clone()).collect()
    }

    /// Each channel's rate in Hz (in the mix's order).
    #[getter]
    fn rates(&self) -> Vec<u64> {
        self.s.mix.channels.iter().map(|c| c.rate_hz).collect()
    }

    /// The modes' names (empty for a mix without modes).
    #[getter]
    fn modes(&self) -> Vec<String> {
        match self.s.modes.len() > 1 {
            true => self
                .s
                .mode_plan()
                .map(|m| m.names.clone())
                .unwrap_or_default(),
            false => Vec::new(),
        }
    }

    /// The frame's period in seconds.
    #[getter]
    fn frame_s(&self) -> f64 {
        self.s.grid.frame_cycles as f64 / self.s.grid.clock_hz as f64
    }

    /// The `[link]` as a dict (`kind`, `baud`, `parity`, `stop_bits`), or None.
    #[getter]
    fn link<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(l) = self.s.mix.link else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("kind", l.kind.name())?;
        d.set_item("baud", l.baud)?;
        d.set_item("parity", l.parity.name())?;
        d.set_item("stop_bits", l.stop_bits)?;
        Ok(Some(d))
    }
}

/// The streaming decoder of a mix's link.
#[pyclass(module = "slotforge._native")]
struct Decoder {
    inner: host::Samples,
    out: Vec<host::Sample>,
}

/// Column bytes (native order) of one field of every sample.
fn column<const N: usize>(xs: &[host::Sample], f: impl Fn(&host::Sample) -> [u8; N]) -> Vec<u8> {
    xs.iter().flat_map(f).collect()
}

#[pymethods]
impl Decoder {
    #[new]
    fn new(mix: &Mix) -> PyResult<Decoder> {
        let inner = host::Samples::new(&mix.s).ok_or_else(|| {
            PyValueError::new_err(format!(
                "mix `{}` has no [link]: its samples leave on the parallel sample port, there is nothing to decode",
                mix.s.mix.name
            ))
        })?;
        Ok(Decoder {
            inner,
            out: Vec::new(),
        })
    }

    /// Feeds received bytes; returns the samples of the packets they
    /// complete as six columns of native-order bytes: frame (u64), slice
    /// (u16), mode (u8), channel (u16), value (u16), sampled_s (f64, NaN
    /// where the schedule has no instant for the record).
    fn push<'py>(&mut self, py: Python<'py>, data: &[u8]) -> Vec<Bound<'py, PyBytes>> {
        self.out.clear();
        self.inner.push(data, &mut self.out);
        let xs = &self.out;
        // `sampled_s` is parsed from the text `decode` writes, so the float
        // is the one a reader of its CSV gets (both correctly rounded)
        let secs = |x: &host::Sample| {
            let t = self.inner.seconds(x);
            t.parse::<f64>().unwrap_or(f64::NAN).to_ne_bytes()
        };
        let cols = [
            column::<8>(xs, |x| x.frame.to_ne_bytes()),
            column::<2>(xs, |x| x.slice.to_ne_bytes()),
            column::<1>(xs, |x| [x.mode]),
            column::<2>(xs, |x| x.channel.to_ne_bytes()),
            column::<2>(xs, |x| x.value.to_ne_bytes()),
            column::<8>(xs, secs),
        ];
        cols.iter().map(|c| PyBytes::new(py, c)).collect()
    }

    /// The counts so far.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        counts(py, self.inner.stats())
    }

    /// The stream ended: the counts, a packet still open counted in `in_flight`.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let st = self.inner.finish();
        counts(py, &st)
    }
}

fn counts<'py>(py: Python<'py>, st: &link::Stats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in [
        ("bytes", st.bytes),
        ("packets", st.packets),
        ("samples", st.samples),
        ("crc_errors", st.crc_errors),
        ("lost", st.lost_packets),
        ("resyncs", st.resyncs),
        ("skipped_bytes", st.skipped_bytes),
        ("overflows", st.overflows.into()),
        ("in_flight", st.in_flight),
    ] {
        d.set_item(k, v)?;
    }
    d.set_item("clean", st.clean())?;
    Ok(d)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Mix>()?;
    m.add_class::<Decoder>()?;
    Ok(())
}
