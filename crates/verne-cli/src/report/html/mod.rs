//! Self-contained HTML pages: the report of `verne verify --html` ([`verify`]) and the 3D
//! views of `verne modes --plot FILE.html` ([`modes`]). A page makes no request of any kind:
//! its styles, scripts (the vendored uPlot, MIT, `assets/report/LICENSE-uPlot.txt`, and the
//! machine's 3D view written for it) and data are inline, and its Content-Security-Policy
//! forbids every fetch (`default-src 'none'`). The data the Rust side computed is one JSON
//! object, its long arrays little-endian typed arrays in base64.

pub mod decimate;
pub mod modes;
pub mod verify;

use std::fmt::Write as _;

use verne::spec::Machine;

/// The vendored plot library (uPlot 1.6.32, MIT).
const UPLOT_JS: &str = include_str!("../../../assets/report/uPlot.iife.min.js");
const UPLOT_CSS: &str = include_str!("../../../assets/report/uPlot.min.css");
/// The page's own style, and the machine's 3D view (canvas 2D, hand-written projection).
const REPORT_CSS: &str = include_str!("../../../assets/report/report.css");
const MACHINE3D_JS: &str = include_str!("../../../assets/report/machine3d.js");

/// Every inline asset, for the test that none can end its `<script>` or `<style>` early.
#[cfg(test)]
pub(crate) const ASSETS: [(&str, &str); 4] = [
    ("uPlot.iife.min.js", UPLOT_JS),
    ("uPlot.min.css", UPLOT_CSS),
    ("report.css", REPORT_CSS),
    ("machine3d.js", MACHINE3D_JS),
];

/// The policy that keeps a page offline: no fetch, frame, font or image from anywhere; inline
/// scripts and styles only.
const CSP: &str = "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'";

/// A page: its title, body (HTML), data (one JSON object) and the scripts that read it.
pub struct Page<'a> {
    pub title: &'a str,
    pub body: &'a str,
    pub data: &'a str,
    /// Whether the page draws plots (includes uPlot).
    pub plots: bool,
    /// The page's own script, run after the 3D view's.
    pub script: &'a str,
}

impl Page<'_> {
    /// The whole document.
    pub fn render(&self) -> String {
        let mut s = String::with_capacity(self.data.len() + 100_000);
        let _ = write!(
            s,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta http-equiv=\"Content-Security-Policy\" content=\"{CSP}\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <meta name=\"generator\" content=\"verne {}\">\n<title>{}</title>\n<style>\n",
            env!("CARGO_PKG_VERSION"),
            escape(self.title)
        );
        if self.plots {
            s.push_str(UPLOT_CSS);
            s.push('\n');
        }
        s.push_str(REPORT_CSS);
        s.push_str("\n</style>\n</head>\n<body>\n");
        s.push_str(self.body);
        s.push_str("\n<script id=\"verne-data\" type=\"application/json\">");
        s.push_str(self.data);
        s.push_str("</script>\n");
        if self.plots {
            s.push_str("<script>\n");
            s.push_str(UPLOT_JS);
            s.push_str("\n</script>\n");
        }
        s.push_str("<script>\n");
        s.push_str(MACHINE3D_JS);
        s.push_str("\n</script>\n<script>\n");
        s.push_str(self.script);
        s.push_str("\n</script>\n</body>\n</html>\n");
        s
    }
}

/// Text for HTML content and attribute values.
pub fn escape(t: &str) -> String {
    let mut s = String::with_capacity(t.len());
    for c in t.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&#39;"),
            c => s.push(c),
        }
    }
    s
}

/// A JSON string that can stand inside a `<script>` element: `<`, `>` and `&` escaped too, so
/// that no text of an input file can close the element.
pub fn json_str(t: &str) -> String {
    let mut s = String::with_capacity(t.len() + 2);
    s.push('"');
    for c in t.chars() {
        match c {
            '"' => s.push_str("\\\""),
            '\\' => s.push_str("\\\\"),
            '<' | '>' | '&' | '\u{2028}' | '\u{2029}' => {
                let _ = write!(s, "\\u{:04x}", c as u32);
            }
            c if (c as u32) < 0x20 => {
                let _ = write!(s, "\\u{:04x}", c as u32);
            }
            c => s.push(c),
        }
    }
    s.push('"');
    s
}

/// A JSON number: the shortest form that reads back as the same f64; `null` where not finite.
pub fn json_num(v: f64) -> String {
    if v.is_finite() {
        let mut b = ryu::Buffer::new();
        let t = b.format_finite(v);
        t.strip_suffix(".0").unwrap_or(t).to_string()
    } else {
        "null".into()
    }
}

/// An optional number.
pub fn json_opt(v: Option<f64>) -> String {
    v.map_or_else(|| "null".into(), json_num)
}

/// Base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        s.push(A[(n >> 18) as usize & 63] as char);
        s.push(A[(n >> 12) as usize & 63] as char);
        s.push(if c.len() > 1 {
            A[(n >> 6) as usize & 63] as char
        } else {
            '='
        });
        s.push(if c.len() > 2 {
            A[n as usize & 63] as char
        } else {
            '='
        });
    }
    s
}

/// Numbers as a little-endian Float32Array in base64 (NaN where a value is missing).
pub fn f32_array(values: impl IntoIterator<Item = f64>) -> String {
    let bytes: Vec<u8> = values
        .into_iter()
        .flat_map(|v| (v as f32).to_le_bytes())
        .collect();
    json_str(&base64(&bytes))
}

/// Integers as a little-endian Uint32Array in base64 (saturated at u32::MAX).
pub fn u32_array(values: impl IntoIterator<Item = u64>) -> String {
    let bytes: Vec<u8> = values
        .into_iter()
        .flat_map(|v| (v.min(u64::from(u32::MAX)) as u32).to_le_bytes())
        .collect();
    json_str(&base64(&bytes))
}

/// The machine's geometry as the 3D view draws it (mm and degrees, the machine file's names):
/// the module of IFToMM 2007 eqs. (3)-(6), the strokes, the tilting table of AIM 2007 eq. (7)
/// and the tool length.
pub fn machine_json(m: &Machine, tool_length: f64) -> String {
    let g = &m.module;
    let l = &m.limits;
    let arr = |v: &[f64]| {
        let items: Vec<String> = v.iter().map(|x| json_num(*x)).collect();
        format!("[{}]", items.join(","))
    };
    format!(
        "{{\"name\":{},\"dx1\":{},\"dx2\":{},\"R1\":{},\"r1\":{},\"L1\":{},\"R2\":{},\"r4\":{},\"L2\":{},\"L3\":{},\
         \"rho_min\":{},\"rho_max\":{},\"rod_tilt_max_deg\":{},\"theta1_min_deg\":{},\"theta1_max_deg\":{},\
         \"d_a\":{},\"d_t\":{},\"tool_length\":{}}}",
        json_str(&m.name),
        json_num(g.dx1),
        json_num(g.dx2),
        json_num(g.r_big1),
        json_num(g.r_small1),
        json_num(g.l1),
        json_num(g.r_big2),
        json_num(g.r4),
        json_num(g.l2),
        json_num(g.l3),
        arr(&l.rho_min),
        arr(&l.rho_max),
        json_num(l.rod_tilt_max.to_degrees()),
        json_num(l.theta1_min.to_degrees()),
        json_num(l.theta1_max.to_degrees()),
        json_num(m.table.d_a),
        json_num(m.table.d_t),
        json_num(tool_length),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_test_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }

    #[test]
    fn json_text_cannot_close_a_script_element() {
        let s = json_str("</script><!-- a\"b\\c\n\u{2028}");
        assert!(!s.to_ascii_lowercase().contains("</script"), "{s}");
        assert!(!s.contains("<!--"), "{s}");
        assert_eq!(
            s,
            "\"\\u003c/script\\u003e\\u003c!-- a\\\"b\\\\c\\u000a\\u2028\""
        );
        assert_eq!(json_num(f64::NAN), "null");
        assert_eq!(json_num(2.0), "2");
        assert_eq!(json_num(0.1), "0.1");
        assert_eq!(json_num(-1.5e-7), "-1.5e-7");
    }

    #[test]
    fn no_inline_asset_ends_its_element_or_names_a_remote_resource() {
        for (name, text) in ASSETS {
            let lower = text.to_ascii_lowercase();
            assert!(!lower.contains("</script"), "{name}");
            assert!(!lower.contains("</style"), "{name}");
            // No stylesheet import or font from elsewhere (the CSP would block them, and the
            // console would show the error).
            assert!(!lower.contains("@import"), "{name}");
            assert!(!lower.contains("url("), "{name}");
        }
    }

    #[test]
    fn a_page_forbids_every_fetch_and_holds_its_data() {
        let page = Page {
            title: "a <title>",
            body: "<main></main>",
            data: "{\"x\":1}",
            plots: true,
            script: "void 0;",
        }
        .render();
        assert!(page.contains("content=\"default-src 'none';"));
        assert!(page.contains("<title>a &lt;title&gt;</title>"));
        assert!(
            page.contains("<script id=\"verne-data\" type=\"application/json\">{\"x\":1}</script>")
        );
        assert!(page.contains("uPlot"));
        for attr in ["src=", "href=\"http"] {
            assert!(!page.contains(attr), "{attr}");
        }
    }
}
