//! The simulator's command line, run as a person runs it: its exit status and what it prints.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

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

/// How long the pseudo-terminal test waits for any one answer before it fails.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(20);
/// The receive buffer a character-counting sender fills (GRBL's 128 bytes).
const SENDER_RX_BUFFER_BYTES: usize = 128;

/// Lines read from the port, by a thread of their own.
struct Port {
    file: std::fs::File,
    lines: mpsc::Receiver<String>,
}

impl Port {
    fn open(path: &str) -> Port {
        let file = std::fs::OpenOptions::new().read(true).write(true).open(path).unwrap();
        let reader = BufReader::new(file.try_clone().unwrap());
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in reader.lines() {
                let Ok(line) = line else { break };
                if tx.send(line.trim_end_matches('\r').to_string()).is_err() {
                    break;
                }
            }
        });
        Port { file, lines }
    }

    fn send(&mut self, bytes: &[u8]) {
        self.file.write_all(bytes).unwrap();
    }

    /// The next line that is not a status report.
    fn answer(&self) -> String {
        loop {
            let line = self.lines.recv_timeout(ANSWER_TIMEOUT).expect("an answer");
            if !line.starts_with('<') && !line.is_empty() {
                return line;
            }
        }
    }

    /// Asks `?` and returns the status report.
    fn status(&mut self) -> String {
        self.send(b"?");
        loop {
            let line = self.lines.recv_timeout(ANSWER_TIMEOUT).expect("a status report");
            if line.starts_with('<') {
                return line;
            }
        }
    }
}

#[test]
fn a_sender_drives_the_simulated_plotter_through_its_pseudo_terminal() {
    let dir = std::env::temp_dir().join(format!("servoplot-pty-{}", std::process::id()));
    let mut child = servoplot()
        .args(["--pty".as_ref(), "--out".as_ref(), dir.as_os_str()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut said = String::new();
    stderr.read_line(&mut said).unwrap();
    // "servoplot simulator: host link on /dev/pts/N (...)"
    let path = said.split_whitespace().find(|w| w.starts_with("/dev/")).unwrap_or_else(|| panic!("{said}"));
    let mut port = Port::open(path);

    // The banner the board sent at power-on waited in the port.
    assert_eq!(port.answer(), "Grbl 1.1h ['$' for help]");
    assert!(port.status().starts_with("<Idle|MPos:0.000,0.000,0.000|"));

    // A square streamed as stream.py streams: as many lines as fit the receive buffer in
    // flight, the next sent as each `ok` frees its bytes.
    let lines = ["G21 G90", "G1 X10 F6000", "G1 Y10", "G1 X0", "G1 Y0", "G1 X5 Y5", "G91", "G1 X1 Y-2", "G90"];
    let mut in_flight: std::collections::VecDeque<usize> = Default::default();
    let mut answers = Vec::new();
    for line in lines {
        let bytes = format!("{line}\n");
        while in_flight.iter().sum::<usize>() + bytes.len() > SENDER_RX_BUFFER_BYTES {
            answers.push(port.answer());
            in_flight.pop_front();
        }
        port.send(bytes.as_bytes());
        in_flight.push_back(bytes.len());
    }
    while in_flight.pop_front().is_some() {
        answers.push(port.answer());
    }
    assert_eq!(answers, vec!["ok"; lines.len()]);
    let mut report = port.status();
    while !report.starts_with("<Idle") {
        std::thread::sleep(Duration::from_millis(200));
        report = port.status();
    }
    assert!(report.starts_with("<Idle|MPos:6.000,3.000,0.000|"), "{report}");

    // Ctrl-C ends the session; the pictures of what was drawn are written, and the clock's
    // figure printed.
    // SAFETY: a signal to the child this test started.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let mut rest = String::new();
    stderr.read_to_string(&mut rest).unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}: {rest}");
    assert!(rest.contains("live session: "), "{rest}");
    assert!(rest.contains("final position: X 6.000 mm, Y 3.000 mm"), "{rest}");
    assert!(std::fs::read_to_string(dir.join("plot.svg")).unwrap().contains("<svg"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_off_power_event_ends_the_run_at_the_cut_and_an_unchanged_card_is_left_alone() {
    let dir = std::env::temp_dir().join(format!("servoplot-power-cut-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (gcode, events, card) = (dir.join("long.gcode"), dir.join("cut.events"), dir.join("card.img"));
    std::fs::write(&gcode, "G1 X100 Y50 F600\nG1 X0 Y0\n").unwrap();
    std::fs::write(&events, "800 off power   # the plug pulled mid-line\n").unwrap();
    let image = servoplot::sim::card::image_of(&[("plot.gcode", b"G1 X5\n")]).unwrap();
    std::fs::write(&card, &image).unwrap();
    let written_at = std::fs::metadata(&card).unwrap().modified().unwrap();
    let out = servoplot()
        .args(["--serial".as_ref(), gcode.as_os_str(), "--events".as_ref(), events.as_os_str()])
        .args(["--sd".as_ref(), card.as_os_str(), "--out".as_ref(), dir.as_os_str()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(stderr.contains("power cut at 0.800 s of virtual time"), "{stderr}");
    let last_pulse_s: f64 = stderr
        .split("last pulse at ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("the summary gives the last pulse: {stderr}"));
    // Given to the ms: a pulse just before the cut reads 0.800.
    assert!(last_pulse_s > 0.7 && last_pulse_s <= 0.8, "pulses until the cut, none after: {last_pulse_s}");
    // The firmware wrote nothing on the card: the image is not rewritten.
    assert!(!stderr.contains("written back"), "{stderr}");
    assert_eq!(std::fs::read(&card).unwrap(), image);
    assert_eq!(std::fs::metadata(&card).unwrap().modified().unwrap(), written_at);

    // `on power` is refused with its line, before anything runs.
    std::fs::write(&events, "100 on power\n").unwrap();
    let out = servoplot().args(["--events".as_ref(), events.as_os_str()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("line 1: the power is on from the start"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}
