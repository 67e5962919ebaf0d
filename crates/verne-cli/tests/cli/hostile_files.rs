//! Hostile inputs to files and streams: closed pipes, non-finite times, line ends, huge grids,
//! outputs that are inputs, duplicated ids, endless input, huge machine files and rows, odd
//! machine files. Each case with the command that shows it and the behaviour it must have.

use crate::common;

use std::io::Read;
use std::os::unix::fs::PermissionsExt;
use std::path::PathBuf;
use std::process::Stdio;

use common::{command, run};

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verne-hostile-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A closed stderr (`verne ik data/example.cl 2>&1 | head -1`): the summary and the
/// failing rows are dropped, the run exits with its own code (1: the file read in inches has
/// unreachable rows), not a panic (101).
#[test]
fn a_closed_stderr_is_not_a_panic() {
    let cases: [(&[&str], i32); 3] = [
        (
            &["ik", "--units", "in", "tests/data/cl-corpus/nx_basic.cls"],
            1,
        ),
        (&["ik", "data/example.cl"], 0),
        (&["ik", "no/such/file.csv"], 2),
    ];
    for (args, code) in cases {
        let mut child = command(args).stderr(Stdio::piped()).spawn().unwrap();
        drop(child.stderr.take()); // the reading end of stderr is closed before any message
        drop(child.stdin.take());
        let mut out = String::new();
        child
            .stdout
            .take()
            .unwrap()
            .read_to_string(&mut out)
            .unwrap();
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(code), "{args:?}");
    }
}

/// A joint table whose `t` is `nan`, `inf` or empty on a row is not "clean": the row is an
/// `input` finding (exit 1).
#[test]
fn verify_does_not_pass_a_time_it_cannot_read() {
    let path = scratch("path.csv");
    std::fs::write(
        &path,
        "x,y,z,i,j,k\n0,0,50,0,0,1\n1,0,50,0,0,1\n2,0,50,0,0,1\n",
    )
    .unwrap();
    let ik = run(&["ik", path.to_str().unwrap()], None);
    assert_eq!(ik.status.code(), Some(0), "{}", stderr(&ik));
    let text = String::from_utf8(ik.stdout).unwrap();
    for bad in ["nan", "inf", ""] {
        let mut joints = String::new();
        for (k, line) in text.lines().enumerate() {
            let cells: Vec<&str> = line.split(',').collect();
            let t = match k {
                0 => "t".to_string(),
                2 => bad.to_string(),
                _ => format!("{}", k as f64 * 0.1),
            };
            joints.push_str(&format!(
                "{},{},{},{},{},{t}\n",
                cells[6], cells[7], cells[8], cells[9], cells[10]
            ));
        }
        let jp = scratch(&format!("joints-{bad}.csv"));
        std::fs::write(&jp, &joints).unwrap();
        let v = run(
            &[
                "verify",
                "--joints",
                jp.to_str().unwrap(),
                "--path",
                path.to_str().unwrap(),
                "--format",
                "json",
            ],
            None,
        );
        let out = String::from_utf8_lossy(&v.stdout);
        assert_eq!(
            v.status.code(),
            Some(1),
            "t = `{bad}`: {out} {}",
            stderr(&v)
        );
        assert!(out.contains("\"clean\":false"), "t = `{bad}`: {out}");
        assert!(out.contains("\"input\":{\"count\":1"), "t = `{bad}`: {out}");
    }
}

/// Line numbers are the file's lines whatever its line ends: LF, CRLF or CR.
#[test]
fn line_numbers_count_crlf_and_cr_lines() {
    for text in [
        "xp,yp,zp\n-240,-86,1000\nbad,1,1\n",
        "xp,yp,zp\r\n-240,-86,1000\r\nbad,1,1\r\n",
        "xp,yp,zp\r-240,-86,1000\rbad,1,1\r",
    ] {
        let o = run(&["ik"], Some(text));
        assert_eq!(o.status.code(), Some(2));
        assert_eq!(
            stderr(&o).lines().next().unwrap(),
            "verne: error: <stdin>:3: column xp: expected a number (mm), found `bad`",
            "{text:?}"
        );
    }
    // The failing-rows summary too: row 2 (line 3) is out of reach.
    let o = run(&["ik"], Some("xp,yp,zp\r\n-240,-86,1000\r\n0,0,1\r\n"));
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("<stdin>:3: "), "{}", stderr(&o));
}

/// A grid too large to count is refused (exit 2), not "0 points".
#[test]
fn a_grid_that_overflows_is_refused() {
    for args in [
        &["workspace", "--step", "1e-300"][..],
        &["workspace", "--bounds", "0,1e300,0,1e300,0,1e300"][..],
    ] {
        let o = run(args, None);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("grid points is more than"),
            "{}",
            stderr(&o)
        );
    }
}

/// An output that is an input of the run is refused before anything is written, under any
/// name; a read-only output is refused; an existing output keeps its mode; an output through a
/// dangling symlink is created where the link points.
#[test]
fn outputs_never_replace_inputs_or_read_only_files() {
    let path = scratch("p7.csv");
    std::fs::write(&path, "x,y,z,i,j,k\n0,0,50,0,0,1\n1,0,50,0,0,1\n").unwrap();
    let p = path.to_str().unwrap();
    let joints = scratch("j7.csv");
    let j = joints.to_str().unwrap();
    assert_eq!(run(&["ik", p, "-o", j], None).status.code(), Some(0));
    let before = std::fs::read(&joints).unwrap();
    // verify --report onto the joint table
    let o = run(&["verify", "--joints", j, "--path", p, "--report", j], None);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is an input of this run"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&joints).unwrap(), before);
    // ik -o onto its input, by a hard link
    let link = scratch("p7-link.csv");
    let _ = std::fs::remove_file(&link);
    std::fs::hard_link(&path, &link).unwrap();
    let o = run(&["ik", p, "-o", link.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("is an input of this run"));
    // read-only target: refused (also as root), untouched
    let ro = scratch("ro.csv");
    std::fs::write(&ro, "keep\n").unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o444)).unwrap();
    let o = run(&["ik", p, "-o", ro.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("read-only"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&ro).unwrap(), b"keep\n");
    // 0600 target keeps 0600
    let private = scratch("private.csv");
    std::fs::write(&private, "old\n").unwrap();
    std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o600)).unwrap();
    assert_eq!(
        run(&["ik", p, "-o", private.to_str().unwrap()], None)
            .status
            .code(),
        Some(0)
    );
    let mode = std::fs::metadata(&private).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o600);
    // dangling symlink: the file is made where it points, the link stays a link
    let target = scratch("made-through-link.csv");
    let _ = std::fs::remove_file(&target);
    let sym = scratch("dangling.csv");
    let _ = std::fs::remove_file(&sym);
    std::os::unix::fs::symlink(&target, &sym).unwrap();
    assert_eq!(
        run(&["ik", p, "-o", sym.to_str().unwrap()], None)
            .status
            .code(),
        Some(0)
    );
    assert!(sym.is_symlink());
    assert!(
        std::fs::read_to_string(&target)
            .unwrap()
            .starts_with("x,y,z")
    );
}

/// A duplicated id in the joint table is fatal with both lines, as in the path.
#[test]
fn a_duplicated_joint_id_is_fatal() {
    let path = scratch("p8.csv");
    std::fs::write(&path, "id,x,y,z,i,j,k\na,0,0,50,0,0,1\nb,1,0,50,0,0,1\n").unwrap();
    let ik = run(&["ik", path.to_str().unwrap()], None);
    let text = String::from_utf8(ik.stdout).unwrap();
    let mut joints = String::new();
    for (k, line) in text.lines().enumerate() {
        let c: Vec<&str> = line.split(',').collect();
        let id = if k == 0 { "id" } else { "a" };
        joints.push_str(&format!(
            "{id},{},{},{},{},{}\n",
            c[7], c[8], c[9], c[10], c[11]
        ));
    }
    let jp = scratch("j8.csv");
    std::fs::write(&jp, joints).unwrap();
    let o = run(
        &[
            "verify",
            "--joints",
            jp.to_str().unwrap(),
            "--path",
            path.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("id `a` appears twice (lines 2 and 3)"),
        "{}",
        stderr(&o)
    );
}

/// Endless or huge input is refused at a bound, naming the line and the limit, not
/// read until memory runs out (`(echo xp,yp,zp; cat /dev/zero) | verne ik`, `-m /dev/zero`,
/// `verify --joints /dev/zero`). Here 17 MiB stand for the endless stream.
#[test]
fn huge_lines_and_machine_files_are_refused_at_a_bound() {
    let zeros = scratch("zeros.csv");
    let mut bytes = b"xp,yp,zp\n".to_vec();
    bytes.resize(bytes.len() + (17 << 20), 0);
    std::fs::write(&zeros, bytes).unwrap();
    let o = run(&["ik", zeros.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        stderr(&o).trim(),
        format!(
            "verne: error: {}: line 2 is longer than 16 MiB: expected CSV text (a header, then rows of numbers)",
            zeros.display()
        )
    );
    let big = scratch("big-machine.toml");
    std::fs::write(&big, vec![b'#'; 17 << 20]).unwrap();
    let o = run(
        &["ik", "-m", big.to_str().unwrap(), "--pose", "1,1,1"],
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("larger than 16 MiB: expected a machine file"),
        "{}",
        stderr(&o)
    );
    let o = run(
        &[
            "verify",
            "--joints",
            "/dev/zero",
            "--path",
            "data/example.cl",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("/dev/zero: line 1 is longer than 16 MiB"),
        "{}",
        stderr(&o)
    );
}

/// a machine file of 40,000 keys and a row of 120,000 columns are read in linear
/// time (measured: 36 s -> 0.6 s and 19.6 s -> 0.03 s, docs/reliability.md; no timing is
/// asserted here). What is checked: every unknown key is reported at its own line, and the
/// wide row is converted with its columns passed through.
#[test]
fn many_keys_and_many_columns_are_read_correctly() {
    let shown = run(&["machine", "show"], None);
    let base = String::from_utf8(shown.stdout).unwrap();
    let junk: String = (0..40_000).map(|i| format!("k{i:05} = 1.0\n")).collect();
    let text = base.replacen("[tool]", &format!("[junk]\n{junk}\n[tool]"), 1);
    let junk_line = text.lines().position(|l| l == "[junk]").unwrap() + 1;
    let m = scratch("many-keys.toml");
    std::fs::write(&m, &text).unwrap();
    let o = run(&["machine", "check", m.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    for i in [0, 12_345, 39_999] {
        let want = format!(":{}: junk.k{i:05}: unknown key", junk_line + 1 + i);
        assert!(err.contains(&want), "{want}");
    }
    let names: Vec<String> = (0..120_000).map(|i| format!("c{i}")).collect();
    let wide = format!(
        "xp,yp,zp,{}\n-240,-86,1000,{}\n",
        names.join(","),
        vec!["1"; names.len()].join(",")
    );
    let w = scratch("wide.csv");
    std::fs::write(&w, wide).unwrap();
    let o = run(&["ik", w.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = String::from_utf8(o.stdout).unwrap();
    let header: Vec<&str> = out.lines().next().unwrap().split(',').collect();
    assert_eq!(header.len(), 3 + 120_000 + 5);
    assert_eq!(header[120_002], "c119999");
}

/// The newcomer's headers: `X,Y,Z,I,J,K` as CAM exports write them give the same joints as the
/// lower-case header; `x` and `X` together are a duplicate; a missing column names the input
/// shapes.
#[test]
fn headers_match_ignoring_case() {
    let lower = run(&["ik"], Some("x,y,z,i,j,k\n10,-20,80,0,0,1\n"));
    let upper = run(&["ik"], Some("X,Y,Z,I,J,K\n10,-20,80,0,0,1\n"));
    assert_eq!(upper.status.code(), Some(0), "{}", stderr(&upper));
    let body = |o: &std::process::Output| {
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .nth(1)
            .unwrap()
            .to_string()
    };
    assert_eq!(body(&lower), body(&upper));
    let dup = run(&["ik"], Some("x,X,y,z\n1,1,1,1\n"));
    assert_eq!(dup.status.code(), Some(2));
    assert!(stderr(&dup).contains("appears twice in the header (names are matched ignoring case)"));
    let missing = run(&["ik"], Some("a,b\n1,2\n"));
    assert!(stderr(&missing).contains("tool poses x,y,z with i,j,k or phi1,phi2"));
}

#[test]
fn negative_step_comment_after_section_and_semicolon_machine_files() {
    let stderr = |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).into_owned();
    // --step -10: the value is read, then refused for its sign (not "unexpected argument -1").
    let s = common::run(&["workspace", "--step", "-10"], None);
    assert_eq!(s.status.code(), Some(2));
    assert!(stderr(&s).contains("positive"), "{}", stderr(&s));
    let dir = std::env::temp_dir().join(format!("verne-machine-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // `[module] # comment` keeps the lines of the keys in that section.
    let base = std::fs::read_to_string(format!("{}/data/verne.toml", common::ROOT)).unwrap();
    let text = base
        .replace("[module]\n", "[module] # the parallel module\n")
        .replace("L1 = 850.0", "L1 = -850.0");
    let line = text
        .lines()
        .position(|l| l.starts_with("L1 = -850.0"))
        .unwrap()
        + 1;
    let f = dir.join("comment.toml");
    std::fs::write(&f, text).unwrap();
    let c = common::run(&["machine", "check", f.to_str().unwrap()], None);
    assert_eq!(c.status.code(), Some(2));
    assert!(
        stderr(&c).contains(&format!("comment.toml:{line}: module.L1")),
        "{}",
        stderr(&c)
    );
    // A key;value file is named for what it is, not "not valid TOML".
    let f = dir.join("semi.csv");
    std::fs::write(&f, "key;value\nmodule.R1;130\n").unwrap();
    let c = common::run(&["machine", "check", f.to_str().unwrap()], None);
    assert_eq!(c.status.code(), Some(2));
    assert!(
        stderr(&c).contains("comma-separated") && !stderr(&c).contains("TOML"),
        "{}",
        stderr(&c)
    );
}

/// Item 9, the rest: control bytes are escaped in messages; a picture path is checked before
/// anything is computed and named once; a long output name still gets a temporary file; stale
/// temporary files of dead runs are removed, a live run's kept; a machine in metres is refused
/// for its rod lengths.
#[test]
fn escapes_early_checks_temp_names_and_tiny_machines() {
    // ESC and NUL from the input are shown escaped, never raw.
    let out = run(&["ik"], Some("xp,yp,zp\n1,2,\x1b[31mX\x00\n"));
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(!err.contains('\x1b') && !err.contains('\0'), "{err:?}");
    assert!(err.contains("\\u{1b}[31mX\\u{0}"), "{err}");

    // A picture into a directory that does not exist: refused before the workspace is sampled,
    // the path named once.
    let out = run(
        &[
            "workspace",
            "--step",
            "5",
            "--plot",
            "/nonexistent-dir/w.svg",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert_eq!(err.matches("/nonexistent-dir/w.svg").count(), 1, "{err}");
    assert!(
        err.contains("does not exist") && !err.contains("points/s"),
        "{err}"
    );
    let out = run(
        &[
            "modes",
            "--joints",
            "674,685,250",
            "--plot",
            "/nonexistent-dir/m.png",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty(), "nothing computed");

    // A 250-byte output name: the temporary name would pass NAME_MAX, a shorter one is used.
    let dir = scratch("escapes");
    std::fs::create_dir_all(&dir).unwrap();
    let long = dir.join(format!("{}.csv", "n".repeat(246)));
    let out = run(
        &["ik", "-q", "-o", long.to_str().unwrap()],
        Some("xp,yp,zp\n0,0,1100\n"),
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(std::fs::read_to_string(&long).unwrap().contains("ok"));

    // A temporary file left by a killed run (a PID that is not running) is removed by the next
    // run to the same target; one of a live process (PID 1) is not.
    let target = dir.join("out.csv");
    let dead = dir.join(".out.csv.verne-4000000.tmp");
    let live = dir.join(".out.csv.verne-1.tmp");
    std::fs::write(&dead, "partial").unwrap();
    std::fs::write(&live, "in progress").unwrap();
    let out = run(
        &["ik", "-q", "-o", target.to_str().unwrap()],
        Some("xp,yp,zp\n0,0,1100\n"),
    );
    assert_eq!(out.status.code(), Some(0));
    assert!(!dead.exists() && live.exists() && target.exists());

    // A machine written in metres: refused for its rods, with the reason.
    let metres = dir.join("metres.toml");
    std::fs::write(
        &metres,
        "base = \"verne\"\n[module]\nL1 = 0.9\nL2 = 0.85\nL3 = 0.85\n",
    )
    .unwrap();
    let out = run(&["machine", "check", metres.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("module.L1") && err.contains("in mm (a file in metres?)"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
