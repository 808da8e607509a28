//! A direct DFT of a channel's samples: the spectrum Figure 7 draws and the
//! apparent frequency it marks.  Samples are uniformly spaced (every
//! interval is exact), so `n` bins up to half the sample rate suffice.

/// Magnitude (in codes, mean removed) at `bins` frequencies from 0 to half
/// the sample rate `fs`; `samples` are `(time_s, code)`.
pub fn spectrum(samples: &[(f64, f64)], fs: f64, bins: usize) -> Vec<(f64, f64)> {
    let n = samples.len() as f64;
    if samples.len() < 4 || bins < 2 {
        return Vec::new();
    }
    let mean = samples.iter().map(|p| p.1).sum::<f64>() / n;
    (0..bins)
        .map(|k| {
            let f = fs / 2.0 * k as f64 / (bins - 1) as f64;
            let w = 2.0 * std::f64::consts::PI * f;
            let (mut re, mut im) = (0.0, 0.0);
            for &(t, v) in samples {
                re += (v - mean) * (w * t).cos();
                im -= (v - mean) * (w * t).sin();
            }
            (f, 2.0 * (re * re + im * im).sqrt() / n)
        })
        .collect()
}

/// The frequency of the strongest bin.
pub fn peak(spectrum: &[(f64, f64)]) -> Option<(f64, f64)> {
    spectrum.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1))
}

/// Where a tone of `f` Hz appears when sampled at `fs`: folded into
/// `0..=fs/2`.
pub fn alias(f: f64, fs: f64) -> f64 {
    let r = f.rem_euclid(fs);
    r.min(fs - r)
}
