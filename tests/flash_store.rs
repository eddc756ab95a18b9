//! End to end: what the host link changes is kept in the simulated board's flash across a power
//! cycle (two runs on the same flash), and flash that reads back wrong is reported.

use servoplot::sim::flash::SimFlash;
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};
use servoplot::store::{STORE_SECTOR_BYTES, STORE_SECTORS, StoreError};

/// Powers the board on with `flash` and sends `input` on the UART link.
fn power_on(flash: SimFlash, input: &str) -> SimReport {
    sim::run(SimConfig { flash, serial: SimSerial::with_input(input.as_bytes()), ..SimConfig::default() })
}

fn answer_lines(report: &SimReport) -> Vec<String> {
    report.answers().lines().map(str::to_string).collect()
}

#[test]
fn settings_offsets_and_startup_blocks_survive_a_power_cycle() {
    let first = power_on(
        SimFlash::default(),
        "$100=80\n$131=150\n$N0=G91\nG10 L2 P2 X5 Y-6\nG0 X10 Y10\nG28.1\n$I=bench plotter\n",
    );
    assert_eq!(first.loaded, Ok(()));
    assert_eq!(first.answers().matches("ok").count(), 7, "{}", first.answers());

    let second = power_on(first.flash.clone(), "$$\n$#\n$N\n$I\nG0 X1\n?\n");
    let answers = answer_lines(&second);
    assert_eq!(second.loaded, Ok(()));
    assert!(answers.contains(&"$100=80.000".to_string()), "{answers:?}");
    assert!(answers.contains(&"$131=150.000".to_string()), "{answers:?}");
    assert!(answers.contains(&"[G55:5.000,-6.000,0.000]".to_string()), "{answers:?}");
    assert!(answers.contains(&"[G28:10.000,10.000,0.000]".to_string()), "{answers:?}");
    assert!(answers.contains(&"$N0=G91".to_string()), "{answers:?}");
    assert!(answers.iter().any(|l| l.starts_with("[VER:") && l.ends_with(":BENCHPLOTTER]")), "{answers:?}");
    // The startup block ran at power-on: G91 makes `G0 X1` a relative move, at 80 steps/mm.
    assert_eq!(answers[2], ">G91:ok", "{answers:?}");
    assert_eq!(second.position.x, 80);
    // The G92 offset is not kept.
    assert!(answers.contains(&"[G92:0.000,0.000,0.000]".to_string()), "{answers:?}");
}

#[test]
fn lines_that_change_nothing_kept_write_nothing() {
    let report = power_on(SimFlash::default(), "$$\n$100=0\n$100=abc\nG10 L2 P9 X1\nG0 X5\n$#\n");
    assert_eq!(report.flash.bytes_changed(), 0, "{}", report.answers());
    assert_eq!(report.answers().matches("error:").count(), 3, "{}", report.answers());
}

#[test]
fn unreadable_flash_is_reported_and_the_defaults_loaded() {
    // Sectors once written by something else.
    let garbage: Vec<u8> = (0..STORE_SECTORS * STORE_SECTOR_BYTES).map(|i| (i * 31 + i / 7) as u8).collect();
    let report = power_on(SimFlash::holding(garbage), "$$\n$100=90\n");
    let answers = answer_lines(&report);
    assert!(!report.timed_out, "{answers:?}");
    assert_eq!(answers[2], "[MSG:Flash store unreadable: defaults loaded]", "{answers:?}");
    assert!(answers.contains(&"$100=100.000".to_string()), "{answers:?}");
    // The store works from then on.
    let again = power_on(report.flash.clone(), "$$\n");
    assert_eq!(again.loaded, Ok(()));
    assert!(answer_lines(&again).contains(&"$100=90.000".to_string()), "{}", again.answers());
}

#[test]
fn a_power_cut_while_saving_a_setting_keeps_the_old_value_or_the_new() {
    let before = power_on(SimFlash::default(), "$100=80\n").flash.bytes();
    let whole = power_on(SimFlash::holding(before.clone()), "$100=90\n").flash;
    let steps = whole.bytes_changed();
    assert!(steps > 0);
    for cut in (0..steps).step_by(7) {
        let flash = SimFlash::holding(before.clone());
        flash.cut_power_after(cut);
        let cut_short = power_on(flash, "$100=90\n");
        assert!(cut_short.answers().contains("[MSG:Flash store failed]"), "{}", cut_short.answers());
        let next = power_on(SimFlash::holding(cut_short.flash.bytes()), "$$\n");
        // A save cut short leaves bytes that are neither a record nor erased: skipped, and said.
        match next.loaded {
            Ok(()) => {}
            Err(StoreError::Repaired) => assert!(
                next.answers().contains("[MSG:Flash store: damaged data skipped, the newest intact record loaded]"),
                "{}",
                next.answers()
            ),
            Err(e) => panic!("cut after {cut} of {steps} bytes: {e:?}"),
        }
        let answers = answer_lines(&next);
        assert!(
            answers.contains(&"$100=80.000".to_string()) || answers.contains(&"$100=90.000".to_string()),
            "cut after {cut} of {steps} bytes: {answers:?}"
        );
    }
}

#[test]
fn a_setting_changed_between_moves_is_saved_only_once_the_pen_stands_still() {
    // On the F407 a save stalls the processor, the pulse interrupt included, for as long as it
    // writes (up to 2 s when it erases a sector): the moves before the line must have ended, and
    // the next may start only after it.
    let report = power_on(SimFlash::default(), "G1 X20 F3000\n$110=4000\nG1 X0\n");
    assert!(report.answers().ends_with("]\r\nok\r\nok\r\nok\r\n"), "{}", report.answers());
    let saves = report.flash.operations_at_us();
    let (Some(&first), Some(&last)) = (saves.first(), saves.last()) else { panic!("nothing saved") };
    assert_eq!(report.flash.erased_sectors().iter().sum::<u32>(), 1, "the first save erases a sector");
    let pulses = &report.trace.pulses;
    let before: Vec<_> = pulses.iter().filter(|p| p.t_us <= last).collect();
    assert_eq!(before.len() * 2, pulses.len(), "the first move whole before the save, the second after");
    let pulse_width_us = report.settings.pulse_width_us as u64;
    assert!(before.last().is_some_and(|p| p.t_us + pulse_width_us < first), "the last pulse had ended");
}
