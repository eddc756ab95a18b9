//! The simulator's command line, run as a person runs it: its exit status and what it prints.

use std::process::{Command, Stdio};

fn servoplot() -> Command {
    Command::new(env!("CARGO_BIN_EXE_servoplot"))
}

#[test]
fn help_into_a_pipe_closed_early_is_no_panic() {
    // As `servoplot --help | head -0`: the reader is gone before the usage is written.
    let mut child = servoplot().arg("--help").stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn a_run_whose_output_pipes_close_early_still_writes_its_pictures() {
    // As `servoplot --serial FILE 2>&1 | head -0`.
    let dir = std::env::temp_dir().join(format!("servoplot-closed-pipe-{}", std::process::id()));
    let gcode = dir.join("line.gcode");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(&gcode, "G1 X5 F3000\n").unwrap();
    let mut child = servoplot()
        .args(["--serial".as_ref(), gcode.as_os_str(), "--out".as_ref(), dir.as_os_str()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    drop(child.stderr.take());
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}");
    let svg = std::fs::read_to_string(dir.join("plot.svg")).unwrap();
    assert!(svg.contains("<svg"), "{svg}");
    std::fs::remove_dir_all(&dir).unwrap();
}
