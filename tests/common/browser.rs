//! Renders a build's `report.html` in headless Chromium (Debian's
//! `chromium`, `make tools`) and reports what a reader would see wrong:
//! images drawn with no size, links to files that are not in the build
//! directory (or anchors to no element), text running out of its box or the
//! page wider than the window.  A screenshot is written beside the report.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs in the page after load; writes its findings as JSON into
/// `<pre id="probe">`, which `--dump-dom` prints.
const PROBE: &str = r#"<script>
(function () {
  const out = {images: 0, empty_images: [], links: [], bad_anchors: [], overflow: []};
  for (const e of document.querySelectorAll('body svg:not(svg svg), img')) {
    out.images++;
    const r = e.getBoundingClientRect();
    if (!(r.width > 0 && r.height > 0)) out.empty_images.push(e.outerHTML.slice(0, 80));
  }
  for (const a of document.querySelectorAll('a[href]')) {
    const h = a.getAttribute('href');
    if (h.startsWith('#')) { if (!document.getElementById(h.slice(1))) out.bad_anchors.push(h); }
    else out.links.push(h);
  }
  for (const e of document.querySelectorAll('body *')) {
    if (e.closest('svg')) continue;
    const st = getComputedStyle(e);
    if (st.overflowX !== 'visible' || st.display === 'inline') continue;
    if (e.scrollWidth > e.clientWidth + 1)
      out.overflow.push(e.tagName + ': ' + (e.textContent || '').trim().slice(0, 60) + ' (' + e.scrollWidth + ' > ' + e.clientWidth + ')');
  }
  if (document.documentElement.scrollWidth > window.innerWidth)
    out.overflow.push('page: ' + document.documentElement.scrollWidth + ' px wide in a ' + window.innerWidth + ' px window');
  const p = document.createElement('pre'); p.id = 'probe';
  p.textContent = JSON.stringify(out); document.body.appendChild(p);
})();
</script>"#;

/// What the probe found.
#[derive(Debug)]
pub struct Rendered {
    pub images: u64,
    pub empty_images: Vec<String>,
    /// Links that are not anchors, as written.
    pub links: Vec<String>,
    pub bad_anchors: Vec<String>,
    pub overflow: Vec<String>,
    pub screenshot: PathBuf,
}

fn chromium(profile: &Path) -> Command {
    let mut c = Command::new("chromium");
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--hide-scrollbars",
    ])
    .arg(format!("--user-data-dir={}", profile.display()))
    .arg("--window-size=1280,1600")
    .arg("--virtual-time-budget=10000");
    c
}

/// Renders `dir/report.html`; writes `dir/report.png`.
pub fn render(dir: &Path) -> Rendered {
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report.html");
    let probe = dir.join(".probe.html");
    std::fs::write(
        &probe,
        html.replace("</body>", &format!("{PROBE}\n</body>")),
    )
    .unwrap();
    let profile = tempfile::tempdir().unwrap();
    let out = chromium(profile.path())
        .arg("--dump-dom")
        .arg(format!("file://{}", probe.display()))
        .output()
        .expect("chromium runs");
    let _ = std::fs::remove_file(&probe);
    let dom = String::from_utf8_lossy(&out.stdout);
    let json = dom
        .split("<pre id=\"probe\">")
        .nth(1)
        .and_then(|r| r.split("</pre>").next())
        .unwrap_or_else(|| {
            panic!(
                "chromium printed no probe result:\n{}\n{}",
                &dom[..dom.len().min(500)],
                String::from_utf8_lossy(&out.stderr)
            )
        });
    let json = json
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&amp;", "&");
    let v: serde_json::Value =
        serde_json::from_str(&json).unwrap_or_else(|e| panic!("{e}: {json}"));
    let list = |k: &str| -> Vec<String> {
        v[k].as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_str().unwrap().to_string())
            .collect()
    };
    let shot = dir.join("report.png");
    let profile = tempfile::tempdir().unwrap();
    let s = chromium(profile.path())
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", dir.join("report.html").display()))
        .output()
        .expect("chromium runs");
    assert!(s.status.success(), "{}", String::from_utf8_lossy(&s.stderr));
    Rendered {
        images: v["images"].as_u64().unwrap(),
        empty_images: list("empty_images"),
        links: list("links"),
        bad_anchors: list("bad_anchors"),
        overflow: list("overflow"),
        screenshot: shot,
    }
}

/// Every complaint about a rendered report, empty when it is fine.
pub fn problems(dir: &Path, r: &Rendered) -> Vec<String> {
    let mut p = Vec::new();
    p.extend(
        r.empty_images
            .iter()
            .map(|i| format!("image with no size: {i}")),
    );
    p.extend(
        r.bad_anchors
            .iter()
            .map(|a| format!("anchor to nothing: {a}")),
    );
    p.extend(r.overflow.iter().map(|o| format!("overflow: {o}")));
    for l in &r.links {
        let f = dir.join(l);
        let inside = f
            .canonicalize()
            .map(|c| c.starts_with(dir.canonicalize().unwrap()))
            .unwrap_or(false);
        if l.contains("://") || !f.is_file() || !inside {
            p.push(format!("link to no file in the build directory: {l}"));
        }
    }
    if std::fs::metadata(&r.screenshot)
        .map(|m| m.len())
        .unwrap_or(0)
        == 0
    {
        p.push("no screenshot".into());
    }
    p
}
