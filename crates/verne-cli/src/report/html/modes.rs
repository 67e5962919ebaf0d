//! `verne modes --plot FILE.html`: every branch of one query in 3D (the module's assembly modes
//! or inverse branches, IFToMM 2007 Figs. 6-7; with the tilting table and the tool for the
//! 5-axis queries), one view per branch, turned together.

use std::fmt::Write as _;

use nalgebra::Vector3;
use verne::parallel_module::equations::{ModulePose, Sliders};
use verne::spec::Machine;

use super::{Page, escape, json_num, json_str, machine_json};

const MODES_JS: &str = include_str!("../../../assets/report/modes.js");

/// One branch to draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch3d {
    /// E.g. `3: s=(-1,-1,-1)`.
    pub label: String,
    /// The verdict (`ok`, or every check that fails, `;`-separated).
    pub detail: String,
    /// The machine's branch (drawn with a highlighted frame).
    pub working: bool,
    pub pose: ModulePose,
    pub rho: Sliders,
    /// The table's angles theta1, theta2 (rad) and the tool tip in the workpiece frame (mm),
    /// for a query of the 5-axis machine.
    pub table: Option<(f64, f64, Vector3<f64>)>,
}

/// The page.
pub fn page(m: &Machine, tool_length: f64, title: &str, branches: &[Branch3d]) -> String {
    let mut d = String::new();
    let _ = write!(
        d,
        "{{\"kind\":\"modes\",\"title\":{},\"machine\":{},\"branches\":[",
        json_str(title),
        machine_json(m, tool_length)
    );
    for (k, b) in branches.iter().enumerate() {
        if k > 0 {
            d.push(',');
        }
        let num3 =
            |v: &Vector3<f64>| format!("[{},{},{}]", json_num(v.x), json_num(v.y), json_num(v.z));
        let _ = write!(
            d,
            "{{\"label\":{},\"detail\":{},\"working\":{},\"rho\":{},\"P\":{},\"alpha\":{}",
            json_str(&b.label),
            json_str(&b.detail.replace(';', ", ")),
            b.working,
            num3(&b.rho),
            num3(&b.pose.p),
            json_num(b.pose.alpha.to_degrees())
        );
        match &b.table {
            Some((t1, t2, tip)) => {
                let _ = write!(
                    d,
                    ",\"theta1\":{},\"theta2\":{},\"tip\":{}}}",
                    json_num(t1.to_degrees()),
                    json_num(t2.to_degrees()),
                    num3(tip)
                );
            }
            None => d.push_str(",\"theta1\":null,\"theta2\":null,\"tip\":null}"),
        }
    }
    d.push_str("]}");
    let mut body = String::new();
    let _ = write!(
        body,
        "<header><h1>{}</h1><p class=\"meta\">machine {} &middot; {} branch{} &middot; verne {}</p></header>\n\
         <p class=\"hint\">Drag a view to turn them all, wheel to zoom, double-click to reset. The machine's branch is framed in green.</p>\n\
         <div id=\"branches\" class=\"branches\"></div>",
        escape(title),
        escape(&m.name),
        branches.len(),
        if branches.len() == 1 { "" } else { "es" },
        env!("CARGO_PKG_VERSION")
    );
    Page {
        title,
        body: &body,
        data: &d,
        plots: false,
        script: MODES_JS,
    }
    .render()
}
