//! Command-line definitions (clap derive). The `///` comments are the help text, written for
//! the terminal (`[verify]`, `<length>`), not for rustdoc.
#![allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

const EXIT_CODES: &str = "\
Exit codes:
  0  success: every row ok (every check passed)
  1  the run finished, but some row is not ok (or a check failed)
  2  fatal: bad arguments, unreadable or malformed input or machine file";

/// Exact kinematics of the VERNE 5-axis parallel kinematic machine tool (and planar glider
/// mechanisms): joint tables from toolpaths, every inverse and forward branch, workspaces.
#[derive(Debug, Parser)]
#[command(name = "verne", version, after_help = EXIT_CODES, max_term_width = 100)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Errors only on stderr: no summaries, warnings or notes (the exit code still tells).
    #[arg(short = 'q', long, global = true)]
    pub quiet: bool,
    /// More on stderr: the machine file, the rows and the rate, the run's time.
    #[arg(short = 'v', long, global = true, conflicts_with = "quiet")]
    pub verbose: bool,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Inverse kinematics: a toolpath (CL file, or CSV of tool tip + axis) -> the five machine
    /// joints; or platform points (xp,yp,zp) -> the parallel module's sliders.
    #[command(
        after_help = "Examples:\n  verne ik data/example.cl -o joints.csv          a CAM job: CL file -> rho1,rho2,rho3,theta1,theta2\n  verne ik data/example-tcp.ngc --format gcode     a tool-centre program -> a joint program\n  verne ik --tool 10,-20,80,0,0,1                  one tool pose X,Y,Z,I,J,K\n  verne ik data/platform_path.csv                  platform points xp,yp,zp (the parallel module)\n  verne ik --all --radians --pose=-240,-86,1000    every branch of one platform point\n\nInputs: a CL file (APT, NX CLSF, Creo, CATIA, SolidWorks CAM); a tool-centre G-code program\n(X Y Z and, by the machine file's [gcode] table, A C = phi1 phi2 or I J K); a CSV of tool\nposes x,y,z with i,j,k or phi1,phi2 (workpiece frame; output adds rho1,rho2,rho3,theta1,theta2,\norientation,flags,status); a CSV of platform points xp,yp,zp (output adds alpha,rho1,rho2,rho3,\nstatus). Column names in any case. --all: one row per real branch.\n\nExit codes: 0 all rows ok, 1 some row not ok, 2 fatal."
    )]
    Ik(IkArgs),
    /// Forward kinematics: machine joints (rho1,rho2,rho3,theta1,theta2) -> tool tip and axis; or
    /// sliders (rho1,rho2,rho3) -> the platform pose (xp, yp, zp, alpha).
    #[command(
        after_help = "Examples:\n  verne ik data/example.cl | verne fk              the tool poses back from the joints\n  verne fk --machine-joints 314.12,260.78,260.60,0,0  one row of machine joints\n  verne fk --all --radians --joints 674,685,250    every assembly mode of three sliders\n\nInputs: machine joints rho1,rho2,rho3 (mm), theta1,theta2 (output adds x,y,z,i,j,k,phi1,phi2,\nstatus); slider rows rho1,rho2,rho3 (output adds xp,yp,zp,alpha,status). --all: one row per\nreal assembly mode.\n\nExit codes: 0 all rows ok, 1 some row not ok, 2 fatal."
    )]
    Fk(FkArgs),
    /// Every branch of one query (a tool pose, machine joints, a platform point or sliders) with
    /// its verdict and Jacobian figures, as a table for a person (or --csv).
    #[command(
        after_help = "Examples:\n  verne modes --tool 80,0,30,0.342020,0,0.939693      every branch of one tool pose (5-axis)\n  verne modes --machine-joints 367.64,320.86,307.56,-20.34,-90  every assembly mode of machine joints\n  verne modes --joints 674,685,250 --plot modes.svg   the four assembly modes of Table III, drawn\n  verne modes --pose=-240,-86,1000 --csv              every inverse branch of a platform point\n\nColumns: the branch's joints (or pose), its configuration s1,s2,s3, working, det A, the extreme\nvelocity amplification factors, the parallel and serial singularity margins, and the status\n(ok, or every check that fails). The title says whether the list is proved complete.\n\nExit codes: 0 some real branch, 1 none (unreachable), 2 fatal."
    )]
    Modes(ModesArgs),
    /// Compare the glider architectures (Wenger 2001): Tables 1 and 2, paper beside computed.
    #[command(
        after_help = "Example:\n  verne design\n  verne design --l 1000 --csv\n  verne design --bounds 1/2,2\n\nTable 1: L0, delta-rho per strut length L and S (largest rectangle) per L^2.\nTable 2: dimensions (m) and envelope (m^2) for a 1 m^2 rectangle, then a square.\n--csv columns: table,mechanism,target,quantity,unit,computed,paper,rel_diff.\n\nExit codes: 0 every mechanism designed, 1 some cannot meet the bounds, 2 fatal."
    )]
    Design(DesignArgs),
    /// Show the default machine file, or check one.
    #[command(subcommand)]
    Machine(MachineCommand),
    /// Workspace on a grid: platform point, tool tip (eq. (27)) or manufacturing workspace
    /// (eq. (26)), constraints (i)-(v) reported separately; volume, bounding box, largest box.
    #[command(
        after_help = "Example:\n  verne workspace --step 10\n  verne workspace --of tool --tool-length 0,50,100,150 --step 10\n  verne workspace --of manufacturing --step 10 -o points.csv --plot ws.svg --slice z=-50\n\nA point is inside when a branch with s=(-1,-1,-1) satisfies every constraint; otherwise its\n`status` is the binding constraint (the reference branch's first failure in the order\nrods_cross, rod_tilt, singularity, stroke, theta1_range) or out_of_reach.\nOutput columns (-o): tool_length,x,y,z,xp,yp,zp,alpha,rho1,rho2,rho3,lambda1,lambda2,lambda3,status,fails.\n\nExit codes: 0 ok, 1 some workspace is empty, 2 fatal."
    )]
    Workspace(WorkspaceArgs),
    /// Round-trip self-test of a machine file over a grid of joints: reports the worst residual.
    #[command(
        after_help = "Example:\n  verne selftest -m my_machine.toml --grid 16\n\nExit codes: 0 every round trip returned, 1 some did not, 2 fatal."
    )]
    Selftest(SelftestArgs),
    /// Check a postprocessor's joint table against the intended tool path: tip and axis errors,
    /// limits (also mid-segment), chordal error, branch flips, singularity proximity, joint jumps,
    /// speeds and accelerations. One report row per violation.
    #[command(after_help = crate::report::verify::help_text())]
    Verify(VerifyArgs),
    /// Calibrate a machine file from measurements of the real machine (tracker, the module
    /// alone, double ballbar, probe), saying what they cannot determine; or plan the poses.
    #[command(
        after_help = CALIBRATE_HELP,
        args_conflicts_with_subcommands = true,
        subcommand_negates_reqs = true
    )]
    Calibrate(CalibrateArgs),
    /// Print a shell completion script.
    #[command(
        after_help = "Example:\n  verne completions bash > ~/.local/share/bash-completion/completions/verne"
    )]
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff), as kept in docs/verne.1: `verne manpage > verne.1`.
    Manpage,
}

/// Options shared by the row commands.
#[derive(Debug, Args)]
pub struct CommonArgs {
    /// Machine file (TOML, or CSV with a `key,value` header). Default: the embedded VERNE machine.
    #[arg(short = 'm', long = "machine", value_name = "FILE")]
    pub machine: Option<PathBuf>,
    /// Angles in radians instead of degrees (input and output).
    #[arg(long)]
    pub radians: bool,
    /// Write numbers with this many decimals (default: shortest exact form).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(0..=17))]
    pub precision: Option<u8>,
}

#[derive(Debug, Args)]
pub struct IkArgs {
    /// Input: a CSV of tool poses (x,y,z with i,j,k or phi1,phi2; workpiece frame), a CSV of
    /// platform points (xp,yp,zp), a CL file (APT, NX CLSF, Creo, CATIA, SolidWorks CAM), or a
    /// tool-centre G-code program (X Y Z and the [gcode] orientation words of the machine file);
    /// absent or `-` reads stdin.
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// How to read INPUT (default: `apt` for a CL file, `gcode` for a G-code program, known by
    /// the extension or the first record or block, else `csv`).
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub input_format: Option<InputFormat>,
    /// One platform point XP,YP,ZP instead of an input file (repeatable). Use
    /// `--pose=-240,-86,1000` for negative values.
    #[arg(long, value_name = "XP,YP,ZP", value_parser = parse_point, conflicts_with_all = ["input", "tool"])]
    pub pose: Vec<[f64; 3]>,
    /// One tool pose X,Y,Z,I,J,K (tip in mm and tool axis, workpiece frame) instead of an input
    /// file (repeatable; rows of one path).
    #[arg(long, value_name = "X,Y,Z,I,J,K", value_parser = parse_tool_pose, conflicts_with = "input", allow_hyphen_values = true)]
    pub tool: Vec<[f64; 6]>,
    /// Tool length Delta (mm), overriding the machine file's.
    #[arg(long, value_name = "MM", value_parser = parse_positive)]
    pub tool_length: Option<f64>,
    /// On the first row of a path, which orientation solution to take when both are feasible.
    #[arg(long, value_enum, default_value = "smallest-theta1")]
    pub prefer: Prefer,
    /// Output format: CSV, a space-separated joint list for LinuxCNC's halstreamer, or a G-code
    /// joint program (`verne verify --joints` reads it back).
    #[arg(long, value_enum, default_value = "csv")]
    pub format: OutputFormat,
    /// Output CSV (written atomically); absent or `-` writes stdout.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Resample the toolpath at this servo period (1ms, 250us, 0.001s) from its feeds: one row
    /// per period, as LinuxCNC's halstreamer plays them; CSV output gains a `t` column (s).
    #[arg(long, value_name = "PERIOD", value_parser = crate::toolpath::resample::parse_period)]
    pub period: Option<f64>,
    /// The machine's rapid rate (mm/min) that times rapid moves under --period.
    #[arg(long, value_name = "MM_MIN", value_parser = parse_positive, requires = "period")]
    pub rapid: Option<f64>,
    /// Every real branch, one row each, instead of the machine's working branch.
    #[arg(long)]
    pub all: bool,
    /// CSV output: insert the poses that keep the tool within --chord-tol and --axis-tol of the
    /// intended move between rows, as the joint program does (rows flagged `inserted`).
    #[arg(long, conflicts_with = "no_linearize")]
    pub linearize: bool,
    /// A joint program or list: one block per path row, without the poses that keep the tool
    /// on the intended move between them.
    #[arg(long)]
    pub no_linearize: bool,
    /// Angular tolerance (degrees) of the joint program's blocks: the tool axis of the
    /// interpolated joints from the intended move's. Default: the machine's chord_axis_error_deg.
    #[arg(long, value_name = "DEG", value_parser = parse_positive)]
    pub axis_tol: Option<f64>,
    /// Write the blocks the drives slow below their programmed feed, as CSV: block, line,
    /// limit, share of it, the time at the feed and the time scheduled (s), the feeds.
    #[arg(long, value_name = "FILE.csv")]
    pub schedule_report: Option<PathBuf>,
    #[command(flatten)]
    pub part: PartArgs,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct FkArgs {
    /// Input CSV with columns rho1,rho2,rho3 (mm), and theta1,theta2 (the table) for the whole
    /// machine; absent or `-` reads stdin.
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// One set of slider positions R1,R2,R3 instead of an input file (repeatable).
    #[arg(long, value_name = "R1,R2,R3", value_parser = parse_point, conflicts_with_all = ["input", "machine_joints"])]
    pub joints: Vec<[f64; 3]>,
    /// One set of machine joints RHO1,RHO2,RHO3,THETA1,THETA2 instead of an input file
    /// (repeatable).
    #[arg(long, value_name = "R1,R2,R3,T1,T2", value_parser = parse_machine_joints, conflicts_with = "input", allow_hyphen_values = true)]
    pub machine_joints: Vec<[f64; 5]>,
    /// Tool length Delta (mm), overriding the machine file's.
    #[arg(long, value_name = "MM", value_parser = parse_positive)]
    pub tool_length: Option<f64>,
    /// Output CSV (written atomically); absent or `-` writes stdout.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Every real assembly mode, one row each, instead of the machine's working mode.
    #[arg(long)]
    pub all: bool,
    /// Where the part sits on the table: X,Y,Z (mm) taken off every tool tip written (the
    /// inverse of `verne ik --offset`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_triple, allow_hyphen_values = true)]
    pub offset: Option<[f64; 3]>,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct ModesArgs {
    /// A platform point XP,YP,ZP: every inverse branch of the parallel module.
    #[arg(long, value_name = "XP,YP,ZP", value_parser = parse_point, required_unless_present_any = ["joints", "tool", "machine_joints"], conflicts_with_all = ["joints", "tool", "machine_joints"])]
    pub pose: Option<[f64; 3]>,
    /// Slider positions R1,R2,R3: every assembly mode of the parallel module.
    #[arg(long, value_name = "R1,R2,R3", value_parser = parse_point, conflicts_with_all = ["tool", "machine_joints"])]
    pub joints: Option<[f64; 3]>,
    /// A tool pose X,Y,Z,I,J,K (tip in mm and tool axis, workpiece frame): every branch of the
    /// 5-axis machine over both orientation solutions of the axis.
    #[arg(long, value_name = "X,Y,Z,I,J,K", value_parser = parse_tool_pose, allow_hyphen_values = true, conflicts_with = "machine_joints")]
    pub tool: Option<[f64; 6]>,
    /// Machine joints R1,R2,R3,T1,T2 (mm, and degrees unless --radians): every assembly mode of
    /// the 5-axis machine, with its tool pose.
    #[arg(long, value_name = "R1,R2,R3,T1,T2", value_parser = parse_machine_joints, allow_hyphen_values = true)]
    pub machine_joints: Option<[f64; 5]>,
    /// Tool length Delta (mm) for --tool and --machine-joints, overriding the machine file's.
    #[arg(long, value_name = "MM", value_parser = parse_positive)]
    pub tool_length: Option<f64>,
    /// CSV for a script instead of an aligned table.
    #[arg(long)]
    pub csv: bool,
    /// Also draw every branch (sliders, rods, platform; front view) to FILE.svg or FILE.png,
    /// or in 3D, one view per branch, to FILE.html.
    #[arg(long, value_name = "FILE.svg|png|html")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Subcommand)]
pub enum MachineCommand {
    /// Print the default machine file (a template to edit), or a preset.
    Show {
        /// The preset: verne (default), biglide1, biglide2, orthoglide. A file of your own
        /// can start from one with `base = "verne"` and give only the keys it changes.
        #[arg(long, value_name = "NAME", default_value = "verne")]
        base: String,
    },
    /// Validate machine files and report every problem of each.
    Check {
        /// The machine files (TOML or key,value CSV; VERNE machines or gliders).
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
}

pub use crate::arg_values::*;
use crate::toolpath::open::ReadOptions;

/// How a toolpath is read and where the part sits (`verne ik`, `verne verify --path`).
#[derive(Debug, Clone, Args)]
pub struct PartArgs {
    /// Units of a CL file or G-code program. Default: what the file says (UNITS, else its feed
    /// words IPM/MMPM; G20/G21), else mm with a warning; given, a file that says otherwise is an
    /// error.
    #[arg(long, value_enum, value_name = "UNITS")]
    pub units: Option<ClUnits>,
    /// Chordal tolerance (mm): of the points interpolated on arcs (a CL file's CIRCLE, G-code's
    /// G2/G3; default 0.005), and of the joint program's blocks (`verne ik`: the tip of the
    /// interpolated joints from the intended move; default the machine's chord_error_mm).
    #[arg(long = "chord-tol", value_name = "MM", value_parser = crate::arg_values::parse_positive)]
    pub chord_tol: Option<f64>,
    /// Where the part sits on the table: X,Y,Z (mm) added to every tool tip read (CAM's part
    /// frame -> the machine's workpiece frame); `verne fk --offset` takes it off again.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_triple, allow_hyphen_values = true)]
    pub offset: Option<[f64; 3]>,
}

impl PartArgs {
    /// The CL reader's options.
    pub fn cl_options(&self) -> verne_cl::Options {
        verne_cl::Options {
            chord_tol_mm: self.arc_tol(),
            units: self.units.map(|u| match u {
                ClUnits::Mm => verne_cl::Units::Mm,
                ClUnits::In => verne_cl::Units::Inch,
            }),
            ..verne_cl::Options::default()
        }
    }

    /// How toolpaths are read: CL files, and G-code with the machine's `[gcode]` words.
    pub fn read_options(&self, words: &verne::spec::gcode::GcodeWords) -> ReadOptions {
        let units = self.units.map(|u| match u {
            ClUnits::Mm => verne_gcode::Units::Mm,
            ClUnits::In => verne_gcode::Units::Inch,
        });
        ReadOptions {
            cl: self.cl_options(),
            gcode: crate::input::gcode::options(self.arc_tol(), units, words),
            words: *words,
        }
    }

    /// The chordal tolerance of arcs (mm).
    pub fn arc_tol(&self) -> f64 {
        self.chord_tol.unwrap_or(verne_cl::DEFAULT_CHORD_TOL_MM)
    }

    /// The part's offset (zero when not given).
    pub fn offset(&self) -> nalgebra::Vector3<f64> {
        self.offset
            .map_or(nalgebra::Vector3::zeros(), nalgebra::Vector3::from)
    }
}

/// Units of a CL file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ClUnits {
    /// Millimetres.
    Mm,
    /// Inches (every length and feed times 25.4).
    In,
}

/// How `verne ik` reads its input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum InputFormat {
    Csv,
    /// A CL file (APT source and the CAM systems' dialects).
    Apt,
    /// A G-code program (RS274/NGC).
    Gcode,
}

/// First-row orientation choice along a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Prefer {
    /// The working branch with the smallest |theta1|.
    SmallestTheta1,
    /// Orientation solution 1: (phi1 >= 0, phi2).
    Orientation1,
    /// Orientation solution 2: (-phi1, phi2 + 180).
    Orientation2,
}

/// Output format of `verne ik`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum OutputFormat {
    Csv,
    /// rho1 rho2 rho3 theta1 theta2 per line, no header (LinuxCNC halstreamer).
    Halstreamer,
    /// A joint program: one G-code block per pose, the joints by the machine file's [gcode]
    /// letters, feed moves in inverse time (G93) at the path's feed.
    Gcode,
}

#[derive(Debug, Args)]
pub struct SelftestArgs {
    /// Machine file (default: the embedded VERNE machine).
    #[arg(short = 'm', long = "machine", value_name = "FILE")]
    pub machine: Option<PathBuf>,
    /// Grid points per slider axis (the grid spans the strokes: N^3 joint sets).
    #[arg(long, value_name = "N", default_value_t = 12, value_parser = clap::value_parser!(u16).range(2..=200))]
    pub grid: u16,
}

/// Which point's workspace `verne workspace` samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum WorkspaceOf {
    /// The platform point P (base frame, z down).
    Platform,
    /// The tool tip, eq. (27) (base frame).
    Tool,
    /// The tool tip in the table frame, the table following the platform (theta1 = alpha).
    Manufacturing,
}

#[derive(Debug, Args)]
pub struct WorkspaceArgs {
    /// Which workspace. Default: platform, or tool when --tool-length is given.
    #[arg(long, value_enum)]
    pub of: Option<WorkspaceOf>,
    /// Tool length(s) in mm, comma-separated: one workspace each, and a table of volume
    /// against tool length. Default: the machine file's.
    #[arg(
        long = "tool-length",
        value_name = "MM[,MM...]",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub tool_length: Vec<f64>,
    /// Grid step (mm), the same along x, y and z [default: 10 mm; for a glider, 801 nodes along
    /// the longer side].
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub step: Option<f64>,
    /// Box sampled (mm, in the workspace's frame). Default: derived from the machine's rod
    /// lengths, rod-tilt limit and strokes (docs/workspace.md).
    #[arg(long, value_name = "XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX", value_parser = parse_bounds, allow_hyphen_values = true)]
    pub bounds: Option<[f64; 6]>,
    /// Bounds on the velocity amplification factors, constraint (iii). Default: 1/3,3.
    #[arg(long, value_name = "LO,HI", value_parser = parse_pair, allow_hyphen_values = true)]
    pub lambda: Option<[f64; 2]>,
    /// Grid points CSV (written atomically; `-` writes stdout and moves the summary to stderr).
    #[arg(short = 'o', long = "output", value_name = "POINTS.csv")]
    pub output: Option<PathBuf>,
    /// Write only the inside points to the CSV.
    #[arg(long, requires = "output")]
    pub inside_only: bool,
    /// Picture of slices and projections, coloured by binding constraint (.svg or .png). With
    /// several tool lengths, one file each, named FILE-L<length>.svg.
    #[arg(long, value_name = "FILE.svg|png")]
    pub plot: Option<PathBuf>,
    /// A slice of the picture (repeatable): z=VALUE (horizontal), or x=VALUE, y=VALUE. Default:
    /// three horizontal slices across the workspace.
    #[arg(long, value_name = "z=VALUE", value_parser = parse_slice, requires = "plot", allow_hyphen_values = true)]
    pub slice: Vec<(usize, f64)>,
    /// Adaptive sampling: a coarse grid (8 steps), refined only where the workspace's boundary
    /// passes; the cost grows with the boundary, not the volume. The default below a 5 mm step
    /// when no points CSV or picture is asked (they need every grid point). For a glider, the
    /// default from 513 nodes, with the points CSV and the picture of the uniform grid.
    #[arg(long, conflicts_with = "uniform")]
    pub adaptive: bool,
    /// Every grid point classified (the default at 5 mm and above, and with -o or --plot; for a
    /// glider, below 513 nodes).
    #[arg(long)]
    pub uniform: bool,
    /// A design sweep: one adaptive workspace per value of a machine-file key, KEY=FROM..TO:N
    /// (e.g. module.L1=800..900:11, tool.length=0..150:7; a glider's alpha1_deg, alpha2_deg,
    /// l1, l2 or l0); twice for a grid of two keys. Writes a CSV table (-o, or stdout): the key
    /// values, volume (a glider's area), bracket, largest box (S), cost.
    #[arg(long, value_name = "KEY=FROM..TO:N", value_parser = crate::arg_values::parse_sweep)]
    pub sweep: Vec<(String, f64, f64, usize)>,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct DesignArgs {
    /// Strut length L in mm: Table 1 also gives L0, delta-rho (mm) and S (mm^2).
    #[arg(long = "l", value_name = "MM", value_parser = crate::arg_values::parse_strut_length)]
    pub l: Option<f64>,
    /// Bounds LO,HI on both velocity amplification factors, eq. (4); fractions like 1/3 allowed.
    /// The paper's values are shown only for the paper's bounds 1/3,3.
    #[arg(long, value_name = "LO,HI", value_parser = parse_lambda_bounds, default_value = "1/3,3")]
    pub bounds: [f64; 2],
    /// Workspace grid nodes along the longer side, for S (more: slower, S closer from below).
    #[arg(long, value_name = "N", default_value_t = 1201, value_parser = clap::value_parser!(u32).range(11..=8001))]
    pub nodes: u32,
    /// CSV for a script (one row per quantity) instead of aligned tables.
    #[arg(long)]
    pub csv: bool,
}

/// How `verne verify` prints its summary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum VerifyFormat {
    /// Aligned text on stderr.
    Text,
    /// One JSON object on stdout (the text summary still goes to stderr).
    Json,
}

#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// Joint table (CSV): rho1,rho2,rho3 (mm), theta1,theta2 (degrees); optional id, t (s) or
    /// feed (mm/min), motion; or a G-code joint program (the letters of the machine file's
    /// [gcode] table; U V W A C by default), its feeds timing the moves.
    #[arg(long, value_name = "POST.csv|ngc")]
    pub joints: PathBuf,
    /// Intended path: CSV with x,y,z and i,j,k or phi1,phi2 (degrees), optional id; a CL
    /// file (APT, NX CLSF, Creo, CATIA, SolidWorks CAM); or a tool-centre G-code program.
    #[arg(long, value_name = "INTENDED.csv|cl|ngc")]
    pub path: PathBuf,
    #[command(flatten)]
    pub part: PartArgs,
    /// Write the text summary to FILE (`-`: stdout) instead of stderr.
    #[arg(long, value_name = "FILE")]
    pub summary: Option<PathBuf>,
    /// Machine file (TOML, or CSV with a `key,value` header); its [verify] table sets thresholds.
    /// Default: the embedded VERNE machine.
    #[arg(short = 'm', long = "machine", value_name = "FILE")]
    pub machine: Option<PathBuf>,
    /// Report CSV, one row per violation: row,check,value,limit,detail (written atomically).
    #[arg(long, value_name = "REPORT.csv")]
    pub report: Option<PathBuf>,
    /// A self-contained HTML report: the verdict, the findings at their lines, plots along the
    /// program and the machine in 3D at any row (no network request; written atomically).
    #[arg(long, value_name = "REPORT.html")]
    pub html: Option<PathBuf>,
    /// JUnit XML for CI test reports: one test suite, one test case per check (written
    /// atomically).
    #[arg(long, value_name = "FILE.xml")]
    pub junit: Option<PathBuf>,
    /// SARIF 2.1.0 for code scanning: one result per finding at its line, the most severe
    /// first, at most 5000 (written atomically).
    #[arg(long, value_name = "FILE.sarif")]
    pub sarif: Option<PathBuf>,
    /// Summary format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: VerifyFormat,
    /// Tool length (mm). Default: the machine file's.
    #[arg(long = "tool-length", value_name = "MM", value_parser = crate::arg_values::parse_positive)]
    pub tool_length: Option<f64>,
    /// A threshold NAME=VALUE (repeatable; overrides the machine file's [verify] table). Names
    /// and defaults are listed below.
    #[arg(long, value_name = "NAME=VALUE", value_parser = crate::arg_values::parse_threshold)]
    pub threshold: Vec<(String, f64)>,
    /// The joints are a recording of the controller's servo samples (LinuxCNC's halsampler, or
    /// a halstreamer stream): whitespace-separated numbers, no header, one line per --period.
    /// Each sample is checked against the nearest point of the path (the contour error), not
    /// paired with a row; speeds and accelerations from the samples' times.
    #[arg(long, requires = "period")]
    pub recording: bool,
    /// The recording's columns, in order: rho1 rho2 rho3 theta1 theta2 (mm, degrees), `tag`
    /// (halsampler -t's sample number) and `_` (unused). Default: rho1,rho2,rho3,theta1,theta2.
    #[arg(long, value_name = "LIST", requires = "recording")]
    pub columns: Option<String>,
    /// The servo period of a recording (1ms, 250us, 0.001s): sample k is at k x period.
    #[arg(long, value_name = "PERIOD", requires = "recording", value_parser = crate::toolpath::resample::parse_period)]
    pub period: Option<f64>,
}

const CALIBRATE_HELP: &str = "\
Examples:
  verne calibrate data/calibration/tracker.csv -o calibrated.toml --report ident.csv
  verne calibrate data/calibration/tracker.csv data/calibration/ballbar.csv -o calibrated.toml
  verne calibrate plan --device tracker --poses 30 -o poses.csv

Measurements (CSV, one device per file; several files are fitted together, each instrument
placed on its own): rho1,rho2,rho3 (mm) and theta1,theta2 (degrees unless --radians; optional
but for a ballbar), then
  x,y,z          the tool tip in the instrument's frame (laser tracker, CMM), optionally i,j,k
                 the tool axis (tip towards spindle)
  xp,yp,zp       the platform point in the instrument's frame (the module alone)
  distance       tool ball to a table ball whose place is unknown (double ballbar)
  height         the tool tip's height on a plane (probe)
The output is a machine file `base = \"<nominal>\"` with the identified keys; the summary says
what the readings cannot determine (those parameters stay at nominal), the 1 sigma of each
identified one, the residuals before and after and on held-out rows (docs/calibration.md).

Exit codes: 0 calibrated, 1 a row or a check failed (nothing written), 2 fatal.";

/// `verne calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    #[command(subcommand)]
    pub plan: Option<CalibrateCommand>,
    /// Measurement files (CSV), one device each.
    #[arg(value_name = "MEAS.csv", required = true)]
    pub measurements: Vec<PathBuf>,
    /// The calibrated machine file (TOML, written atomically).
    #[arg(
        short = 'o',
        long = "output",
        value_name = "FILE.toml",
        required = true
    )]
    pub output: Option<PathBuf>,
    /// The identifiability report (CSV): parameters, combinations held, instrument,
    /// correlations, residuals.
    #[arg(long, value_name = "FILE.csv")]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub fit: CalibrateFitArgs,
    #[command(flatten)]
    pub common: CommonArgs,
}

/// The options of a fit (`verne calibrate` and its plan).
#[derive(Debug, Args)]
pub struct CalibrateFitArgs {
    /// The machine-file keys the fit may move (comma-separated), instead of those of the
    /// devices (module.*, zeros.rho1..3, tool.length; a ballbar: zeros, tool.length, table.*).
    #[arg(long, value_name = "KEYS", value_delimiter = ',')]
    pub free: Vec<String>,
    /// Keys held at their nominal values (comma-separated).
    #[arg(long, value_name = "KEYS", value_delimiter = ',')]
    pub fixed: Vec<String>,
    /// The readings' noise, 1 sigma per coordinate (mm): the weights, and a plan's sigmas.
    #[arg(long, value_name = "MM", default_value_t = verne::calibrate::DEFAULT_NOISE.length_mm, value_parser = parse_positive)]
    pub noise: f64,
    /// The tool axis's noise, 1 sigma per coordinate (rad).
    #[arg(long, value_name = "RAD", default_value_t = verne::calibrate::DEFAULT_NOISE.axis_rad, value_parser = parse_positive)]
    pub noise_axis: f64,
    /// A prior bound KEY=BOUND (mm, degrees for angles; repeatable): a fit that moves the key
    /// farther from nominal is refused. Default 5 mm, 1 degree.
    #[arg(long, value_name = "KEY=BOUND", value_parser = crate::cmd::calibrate::parse_prior)]
    pub prior: Vec<(String, f64)>,
    /// Accept parameters that move beyond their prior bounds.
    #[arg(long)]
    pub allow_large: bool,
    /// Folds of the hold-out (each fold's rows predicted by a fit of the others; 0: none).
    #[arg(long, value_name = "K", default_value_t = verne::calibrate::DEFAULT_FOLDS as u32, value_parser = clap::value_parser!(u32).range(0..=1000))]
    pub folds: u32,
}

/// `verne calibrate plan`.
#[derive(Debug, Subcommand)]
pub enum CalibrateCommand {
    /// Plan the poses to measure: joint sets inside the workspace that maximise the
    /// determinant of the information matrix (D-optimal), with the predicted 1 sigma of every
    /// parameter and of the tool tip.
    Plan(CalibratePlanArgs),
}

/// The devices of a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CalibrationDevice {
    /// Tool tip in the instrument's frame (laser tracker, CMM).
    Tracker,
    /// The platform point (the module alone).
    Platform,
    /// Double ballbar: tool ball to a table ball.
    Ballbar,
    /// Heights of the tool tip on a plane.
    Probe,
}

#[derive(Debug, Args)]
pub struct CalibratePlanArgs {
    /// The instrument.
    #[arg(long, value_enum)]
    pub device: CalibrationDevice,
    /// Poses to measure.
    #[arg(long, value_name = "N", default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=100000))]
    pub poses: u32,
    /// Candidate poses drawn inside the workspace.
    #[arg(long, value_name = "N", default_value_t = 1500, value_parser = clap::value_parser!(u32).range(1..=200000))]
    pub candidates: u32,
    /// A tracker also reads the tool axis.
    #[arg(long)]
    pub axis: bool,
    /// Ballbar: the bar's length (mm).
    #[arg(long, value_name = "MM", default_value_t = 100.0, value_parser = parse_positive)]
    pub bar: f64,
    /// Ballbar: the table ball in the workpiece frame X,Y,Z (mm).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_triple, allow_hyphen_values = true)]
    pub ball: Option<[f64; 3]>,
    /// Seed of the candidates' draw.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub seed: u64,
    /// The poses (CSV): joints, and what the nominal machine's instrument would read there.
    #[arg(short = 'o', long = "output", value_name = "FILE.csv")]
    pub output: Option<PathBuf>,
    /// The predicted sigmas (CSV).
    #[arg(long, value_name = "FILE.csv")]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub fit: CalibrateFitArgs,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_definition_is_consistent() {
        Cli::command().debug_assert();
    }
}
