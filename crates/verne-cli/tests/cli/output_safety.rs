//! Output safety: an interrupted run leaves no partial and no temporary file; a full disk and a
//! closed pipe end the run cleanly; every input row yields exactly one output row; a device or a
//! symlink given as the output is written, not replaced.

use std::io::Write;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_verne");

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("verne-safety-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// stdout of `verne ARGS` fed `input` on stdin (written from another thread, so a large input
/// cannot deadlock against a full stdout pipe), optionally with RAYON_NUM_THREADS set.
fn piped(args: &[&str], input: &str, threads: Option<&str>) -> Vec<u8> {
    let mut cmd = Command::new(BIN);
    cmd.args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null());
    if let Some(t) = threads {
        cmd.env("RAYON_NUM_THREADS", t);
    }
    let mut child = cmd.spawn().unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let text = input.to_string();
    let writer = std::thread::spawn(move || stdin.write_all(text.as_bytes()));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    out.stdout
}

/// A module path of `n` rows inside the workspace.
fn path_csv(n: usize) -> String {
    let mut s = String::from("xp,yp,zp\n");
    for k in 0..n {
        let a = k as f64 * 1e-3;
        s.push_str(&format!(
            "{},{},1050\n",
            -250.0 + 80.0 * a.cos(),
            90.0 * a.sin()
        ));
    }
    s
}

#[test]
fn interrupted_run_leaves_no_file_behind() {
    let dir = temp_dir("kill");
    let target = dir.join("joints.csv");
    for (signal, number) in [("INT", 2), ("TERM", 15), ("HUP", 1)] {
        let mut child = Command::new(BIN)
            .args(["ik", "-o", target.to_str().unwrap()])
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Feed some rows and keep stdin open, so the run is in progress when the signal comes.
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(path_csv(20_000).as_bytes()).unwrap();
        stdin.flush().unwrap();
        let deadline = Instant::now() + Duration::from_secs(20);
        // Wait until the temporary file exists (the run has started writing).
        while std::fs::read_dir(&dir).unwrap().count() == 0 && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        let status = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let code = child.wait().unwrap();
        drop(stdin);
        assert_eq!(
            code.code(),
            Some(128 + number),
            "SIG{signal}: exit code 128 + {number}, as a shell reports it"
        );
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert!(left.is_empty(), "SIG{signal} left {left:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_full_disk_is_a_clean_fatal_error() {
    if !std::path::Path::new("/dev/full").exists() {
        return;
    }
    let mut child = Command::new(BIN)
        .args(["ik"])
        .stdin(Stdio::piped())
        .stdout(
            std::fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .unwrap(),
        )
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(path_csv(100).as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("<stdout>") && err.contains("No space left on device"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_closed_pipe_ends_the_run_quietly() {
    let dir = temp_dir("pipe");
    let input = dir.join("in.csv");
    std::fs::write(&input, path_csv(50_000)).unwrap();
    let mut child = Command::new(BIN)
        .args(["ik", input.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read one line, then close our end of the pipe.
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 16];
    std::io::Read::read_exact(&mut stdout, &mut first).unwrap();
    drop(stdout);
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_input_row_yields_one_output_row() {
    // A deterministic mix of reachable, unreachable, invalid and degenerate rows.
    let mut s = String::from("id,xp,yp,zp\n");
    let mut x: u64 = 0x9e3779b97f4a7c15;
    let n = 3000;
    for k in 0..n {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let f = |sh: u32| ((x >> sh) & 0xffff) as f64 / 65535.0;
        let cell = |v: f64, kind: u64| match kind % 17 {
            0 => "NaN".to_string(),
            1 => String::new(),
            2 => "1e308".to_string(),
            3 => "0".to_string(),
            _ => v.to_string(),
        };
        s.push_str(&format!(
            "{k},{},{},{}\n",
            cell(-1200.0 + 2000.0 * f(0), x >> 5),
            cell(-900.0 + 1800.0 * f(16), x >> 9),
            cell(-200.0 + 2500.0 * f(32), x >> 13)
        ));
    }
    for all in [false, true] {
        let args: &[&str] = if all { &["ik", "--all"] } else { &["ik"] };
        let text = String::from_utf8(piped(args, &s, None)).unwrap();
        let ids: Vec<usize> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().parse().unwrap())
            .collect();
        if all {
            // Branch rows of one input row are contiguous; every id appears, in order.
            let mut distinct = ids.clone();
            distinct.dedup();
            assert_eq!(distinct, (0..n).collect::<Vec<_>>());
        } else {
            assert_eq!(ids, (0..n).collect::<Vec<_>>());
        }
    }
}

/// The output does not depend on the number of threads: batches and runs start at fixed rows,
/// so `verne fk`'s tracking restarts at the same rows whatever the pool.
#[test]
fn output_is_the_same_with_one_and_two_threads() {
    let run = |args: &[&str], input: &str, threads: &str| piped(args, input, Some(threads));
    let path = path_csv(5000);
    let joints = run(&["ik"], &path, "2");
    assert_eq!(joints, run(&["ik"], &path, "1"));
    let joints = String::from_utf8(joints).unwrap();
    assert_eq!(joints.lines().count(), 5001);
    for args in [&["fk"][..], &["fk", "--all"][..]] {
        let two = run(args, &joints, "2");
        assert!(two.len() > joints.len(), "{args:?}");
        assert_eq!(two, run(args, &joints, "1"), "{args:?}");
        assert_eq!(two, run(args, &joints, "3"), "{args:?}");
    }
}

/// An output path that is a device or a symlink stays what it is: `/dev/null` is written in place
/// (a temporary file renamed over it would replace the device node, for root), and a symlink
/// keeps pointing at its file, which now holds the output.
#[cfg(unix)]
#[test]
fn devices_and_symlinks_are_written_not_replaced() {
    use std::os::unix::fs::FileTypeExt;
    let pose = "--pose=-240,-86,1000";
    let status = Command::new(BIN)
        .args(["ik", pose, "-o", "/dev/null"])
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let null = std::fs::metadata("/dev/null").unwrap().file_type();
    assert!(null.is_char_device(), "/dev/null is no longer a device");

    let d = temp_dir("symlink");
    std::fs::write(d.join("real.csv"), "old\n").unwrap();
    std::os::unix::fs::symlink("real.csv", d.join("link.csv")).unwrap();
    let status = Command::new(BIN)
        .args(["ik", pose, "-o"])
        .arg(d.join("link.csv"))
        .status()
        .unwrap();
    assert!(status.success());
    let link = std::fs::symlink_metadata(d.join("link.csv")).unwrap();
    assert!(link.file_type().is_symlink(), "the symlink was replaced");
    let text = std::fs::read_to_string(d.join("real.csv")).unwrap();
    assert!(text.starts_with("xp,yp,zp,alpha,"), "{text}");
    assert_eq!(text.lines().count(), 2, "{text}");
    let _ = std::fs::remove_dir_all(&d);
}
