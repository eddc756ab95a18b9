//! The simulator's command line: feeds the simulated board from files, standard input or the
//! built-in demo, prints the serial answers, and writes the plot and the LCD frames.

use std::format;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::string::String;
use std::vec::Vec;

use crate::sim::inputs::{InputScript, Switches};
use crate::sim::{self, KeysStart, SimConfig, flash::SimFlash, keys::KeyScript, picture, pty::Pty, serial::SimSerial};
use crate::store::STORE_SECTORS;

/// The built-in demo: a drawing streamed over the serial link, then one drawn from the keypad.
const DEMO_GCODE: &str = include_str!("../../demo/demo.gcode");
const DEMO_KEYS: &str = include_str!("../../demo/demo.keys");

/// The built-in demo, as `servoplot` with no input runs it: the PC's drawing streamed over the
/// serial link, then the keypad script, once that drawing is done.
pub fn demo() -> Result<SimConfig, String> {
    Ok(SimConfig {
        serial: SimSerial::with_input(DEMO_GCODE.as_bytes()),
        keys: KeyScript::parse(DEMO_KEYS).map_err(|e| format!("demo/demo.keys: {e}"))?,
        keys_start: KeysStart::AfterSerial,
        ..SimConfig::default()
    })
}

/// At most this many LCD frames are written as PNG files (the last frame always is).
const LCD_PNG_MAX_FRAMES: usize = 300;

const USAGE: &str = "\
usage: servoplot [--serial FILE|- | --pty] [--keys FILE] [--keys-text SCRIPT] [--cpu f407]
                 [--flash FILE] [--switches MM] [--events FILE] [--sd IMAGE | --sd-dir DIR]
                 [--out DIR]

Runs the plotter firmware on a simulated board. With no --serial, --pty or --keys it draws the
built-in demo. Serial answers go to standard output; the pen path (rebuilt from the emitted
pulses) goes to DIR/plot.svg, the first 300 LCD frames that differ from the one before to
DIR/lcd/*.png, the last to DIR/lcd-final.png, and all of them to DIR/session.gif (DIR
defaults to `out`).

  --serial FILE   host-link input, as a GRBL sender would send it (`-` = standard input)
  --pty           serve the host link on a pseudo-terminal: its path is printed, for a sender
                  or a terminal to open as a serial port; time passes as on the wall clock,
                  and Ctrl-C ends the session
  --keys FILE     keypad script: keys like `1 # A`, `8:1500` holds 8 for 1.5 s, `wait:500`;
                  with --serial FILE it starts once the file's last line is answered
                  and the pen rests (the first key then puts the DONE screen away)
  --keys-text S   the keypad script given inline
  --cpu f407      let the firmware's work take the time it takes on the STM32F407 (as counted
                  on a Cortex-M4F); the summary then tells whether the pulses ever had to wait
  --flash FILE    the board's flash store (settings, offsets, startup blocks), kept in FILE:
                  read at power-on, written as the firmware saves; created erased if missing.
                  Two runs with the same FILE are a power cycle. Without it the flash starts
                  erased and is forgotten.
  --switches MM   limit switches MM beyond each end of the travel ($130, $131 either way of
                  where the pen starts; negative: inside it), normally open ($5=0); they stop
                  the pen when hard limits are on ($21=1)
  --events FILE   input events at set times, one per line: `<ms> on|off <input>`, the input
                  one of x- x+ y- y+ (a switch stuck pressed, or let go), alarm-x alarm-y (a
                  driver's alarm output, watched with $207=1), estop (watched with $208=1) or
                  card-out (the card taken out; off puts it back); `<ms> off power` cuts the
                  power then (once): the run ends at that instant, whatever it was doing
  --sd IMAGE      a microSD card in the slot: IMAGE is a FAT16 or FAT32 image (e.g.
                  `mkfs.fat -F 16 -C card.img 16384` then `mcopy -i card.img plot.gcode ::`);
                  the keypad's card mode lists its G-code files and plots the one chosen.
                  The card is kept in IMAGE: what the plotter writes on it (its resume record)
                  is there for the next run (written back at the end, cut or not, if changed).
                  Two runs with the same IMAGE and `off power` in the first are a power cut.
  --sd-dir DIR    the same with a card made from the files in DIR; what the plotter writes
                  on it is forgotten (nothing is written to DIR)
  --out DIR       where the pictures go

Set SERVOPLOT_LOG=info (or debug, trace) to see the firmware's log on standard error.";

/// A line on standard error; a closed standard error (`servoplot 2>&1 | head`) loses it, and
/// nothing else.
macro_rules! note {
    ($($arg:tt)*) => {{
        let _ = std::writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// Firmware log lines on standard error, stamped with virtual time; the level comes from the
/// `SERVOPLOT_LOG` variable (`error`, `warn`, `info`, `debug`, `trace`), off when it is unset.
struct StderrLog;

impl log::Log for StderrLog {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::max_level()
    }

    fn log(&self, record: &log::Record) {
        let t_s = sim::clock::now_ticks() as f64 / 1e6;
        note!("{t_s:10.6} {:<5} {}", record.level(), record.args());
    }

    fn flush(&self) {}
}

fn init_log() {
    let level = match std::env::var("SERVOPLOT_LOG").as_deref() {
        Ok("error") => log::LevelFilter::Error,
        Ok("warn") => log::LevelFilter::Warn,
        Ok("info") => log::LevelFilter::Info,
        Ok("debug") => log::LevelFilter::Debug,
        Ok("trace") => log::LevelFilter::Trace,
        _ => return,
    };
    static LOG: StderrLog = StderrLog;
    if log::set_logger(&LOG).is_ok() {
        log::set_max_level(level);
    }
}

struct Args {
    serial: Option<String>,
    pty: bool,
    keys: Option<String>,
    cpu: Option<sim::cpu::CpuModel>,
    flash: Option<PathBuf>,
    switches: Option<Switches>,
    events: InputScript,
    card: Option<sim::card::SimCard>,
    /// The image file the card is kept in (`--sd`; none with `--sd-dir`).
    sd_image: Option<PathBuf>,
    out: PathBuf,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        serial: None,
        pty: false,
        keys: None,
        cpu: None,
        flash: None,
        switches: None,
        events: InputScript::default(),
        card: None,
        sd_image: None,
        out: PathBuf::from("out"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--serial" => args.serial = Some(value()?),
            "--pty" => args.pty = true,
            "--keys" => {
                let path = value()?;
                args.keys = Some(std::fs::read_to_string(&path).map_err(|e| format!("{path}: {e}"))?);
            }
            "--keys-text" => args.keys = Some(value()?),
            "--cpu" => match value()?.as_str() {
                "f407" => args.cpu = Some(sim::cpu::CpuModel::f407()?),
                other => return Err(format!("unknown processor `{other}` (there is: f407)")),
            },
            "--flash" => args.flash = Some(PathBuf::from(value()?)),
            "--switches" => {
                let mm = value()?;
                let beyond_travel_mm = mm.parse::<f32>().ok().filter(|v| v.is_finite());
                let beyond_travel_mm =
                    beyond_travel_mm.ok_or_else(|| format!("--switches: `{mm}` is no distance in mm"))?;
                args.switches = Some(Switches { beyond_travel_mm });
            }
            "--events" => {
                let path = value()?;
                let text = std::fs::read_to_string(&path).map_err(|e| format!("{path}: {e}"))?;
                args.events = InputScript::parse(&text).map_err(|e| format!("{path}: {e}"))?;
            }
            "--sd" => {
                let path = PathBuf::from(value()?);
                args.card = Some(sim::card::card_from_image(&path)?);
                args.sd_image = Some(path);
            }
            "--sd-dir" => {
                args.card = Some(sim::card::card_from_dir(Path::new(&value()?))?);
                args.sd_image = None;
            }
            "--out" => args.out = PathBuf::from(value()?),
            "-h" | "--help" => return Err(String::new()),
            other => return Err(format!("unknown argument `{other}`")),
        }
    }
    if args.pty && args.serial.is_some() {
        return Err("--pty and --serial both feed the host link: give one of them".into());
    }
    Ok(args)
}

/// Runs the simulator with the process' command line; the firmware binary's `main` on the host.
pub fn main() -> ExitCode {
    init_log();
    let args = match parse_args() {
        Ok(a) => a,
        // `--help` asked for the usage: it goes to standard output and is no error.
        Err(e) if e.is_empty() => {
            // `servoplot --help | head` closes the pipe early: what is cut is no error.
            let _ = std::writeln!(std::io::stdout(), "{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            note!("error: {e}");
            note!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    let (serial, keys, keys_start) = match inputs(&args) {
        Ok(inputs) => inputs,
        Err(e) => {
            note!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let flash = match &args.flash {
        Some(path) => match SimFlash::in_file(path, STORE_SECTORS) {
            Ok(flash) => flash,
            Err(e) => {
                note!("error: --flash {}: {e}", path.display());
                return ExitCode::from(2);
            }
        },
        None => SimFlash::default(),
    };
    let with_cpu = args.cpu.is_some();
    let live = serial.is_live();
    // The image the card began with, to tell whether the run changed it.
    let sd_before = args.sd_image.clone().zip(args.card.as_ref().map(sim::card::SimCard::image));
    let report = sim::run(SimConfig {
        flash,
        serial: serial.echo_to_stdout(),
        keys,
        keys_start,
        cpu: args.cpu,
        switches: args.switches,
        events: args.events,
        card: args.card,
        stop: live.then(sim::stop::on_ctrl_c),
        ..SimConfig::default()
    });
    if let Some(off_us) = report.power_off_us {
        note!("power cut at {:.3} s of virtual time: the run ended there", off_us as f64 / 1e6);
    }
    // A card not written back is an error, but the pictures are still made.
    let mut card_kept = true;
    if let (Some((path, before)), Some(after)) = (&sd_before, &report.card_image) {
        match sim::card::keep_image(path, before, after) {
            Ok(true) => note!("the card as the run left it: written back to {}", path.display()),
            Ok(false) => {}
            Err(e) => {
                note!("error: --sd {}: writing the card back: {e}", path.display());
                card_kept = false;
            }
        }
    }
    if let Some((wall_us, virtual_us)) = report.live_kept_us {
        // How well the virtual clock kept to the wall clock while the session was live.
        let (wall_s, virtual_s) = (wall_us as f64 / 1e6, virtual_us as f64 / 1e6);
        note!(
            "live session: {wall_s:.3} s of wall time, {virtual_s:.3} s of virtual time ({:.3}x)",
            virtual_s / wall_s.max(f64::MIN_POSITIVE)
        );
    }
    if with_cpu {
        note!("step-queue underruns on the modelled STM32F407: {}", report.underruns);
    }
    if report.missed_updates > 0 {
        note!("missed step timer updates: {}", report.missed_updates);
    }
    match write_pictures(&report, &args.out) {
        Ok(()) => {}
        Err(e) => {
            note!("error: writing pictures to {}: {e}", args.out.display());
            return ExitCode::FAILURE;
        }
    }
    if report.timed_out {
        note!(
            "error: the machine did not come to rest within {} s of virtual time",
            sim::SIM_MAX_VIRTUAL_US / 1_000_000
        );
        return ExitCode::FAILURE;
    }
    if !card_kept {
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}

/// The host link and the keypad script the command line asks for: the built-in demo if it asks
/// for neither.
fn inputs(args: &Args) -> Result<(SimSerial, KeyScript, KeysStart), String> {
    let keys = args.keys.as_deref().map(KeyScript::parse).transpose().map_err(|e| format!("keypad script: {e}"))?;
    if args.pty {
        let pty = Pty::open().map_err(|e| format!("--pty: {e}"))?;
        note!(
            "servoplot simulator: host link on {} (connect a sender or a terminal to it; Ctrl-C ends)",
            pty.path().display()
        );
        let serial = SimSerial::from_pty(pty).map_err(|e| format!("--pty: {e}"))?;
        return Ok((serial, keys.unwrap_or_default(), KeysStart::AtOnce));
    }
    if args.serial.is_none() && args.keys.is_none() {
        note!("servoplot simulator: no input given, drawing the built-in demo");
        let demo = demo()?;
        return Ok((demo.serial, demo.keys, demo.keys_start));
    }
    let (serial, keys_start) = match args.serial.as_deref() {
        // A person at the terminal: the keys start at once.
        Some("-") => (SimSerial::from_stdin(), KeysStart::AtOnce),
        // A file: the keys start once its drawing is done.
        Some(path) => {
            let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
            (SimSerial::with_input(&bytes), KeysStart::AfterSerial)
        }
        None => (SimSerial::default(), KeysStart::AtOnce),
    };
    Ok((serial, keys.unwrap_or_default(), keys_start))
}

fn write_pictures(report: &sim::SimReport, out: &Path) -> std::io::Result<()> {
    let lcd_dir = out.join("lcd");
    std::fs::create_dir_all(&lcd_dir)?;
    for old in std::fs::read_dir(&lcd_dir)? {
        let old = old?.path();
        if old.extension().is_some_and(|e| e == "png") {
            std::fs::remove_file(old)?;
        }
    }
    let svg_path = out.join("plot.svg");
    let mut svg = std::io::BufWriter::new(std::fs::File::create(&svg_path)?);
    picture::write_plot_svg(&report.strokes(), report.settings.steps_per_mm, &mut svg)?;

    // Consecutive identical frames are one picture.
    let mut distinct: Vec<&(u64, sim::lcd::Frame)> = Vec::new();
    for f in &report.frames {
        if distinct.last().is_none_or(|last| last.1 != f.1) {
            distinct.push(f);
        }
    }
    let written = distinct.len().min(LCD_PNG_MAX_FRAMES);
    for (i, (t_us, frame)) in distinct.iter().take(written).enumerate() {
        picture::write_frame_png(frame, &lcd_dir.join(format!("frame-{:04}-{:08}ms.png", i + 1, t_us / 1000)))?;
    }
    if let Some((_, last)) = distinct.last() {
        picture::write_frame_png(last, &out.join("lcd-final.png"))?;
    }
    let session: Vec<(u64, sim::lcd::Frame)> = distinct.iter().map(|&f| f.clone()).collect();
    picture::write_session_gif(&session, &out.join("session.gif"))?;
    let [xf, xb, yf, yb] = report.trace.counts();
    let mm = |axis: usize, steps: i32| steps as f32 / report.settings.steps_per_mm[axis];
    note!("");
    note!("pulses: X {xf} forward, {xb} back; Y {yf} forward, {yb} back");
    note!(
        "final position: X {:.3} mm, Y {:.3} mm; last pulse at {:.3} s of virtual time",
        mm(0, report.position.x),
        mm(1, report.position.y),
        report.last_pulse_us() as f64 / 1e6
    );
    note!("plot (rebuilt from the pulses): {}", svg_path.display());
    note!(
        "LCD frames: {} sent, {} distinct, {written} written to {}{}",
        report.frames.len(),
        distinct.len(),
        lcd_dir.display(),
        if written < distinct.len() { " (the rest are left out; the last is lcd-final.png)" } else { "" }
    );
    if !distinct.is_empty() {
        note!("final LCD frame: {}", out.join("lcd-final.png").display());
    }
    note!("the LCD through the whole session, animated: {}", out.join("session.gif").display());
    Ok(())
}
