//! The `$` commands, and which states refuse what: GRBL's locks for alarms, jogs and homing, and
//! the commands that wait behind a running program.

use super::*;

#[test]
fn alarm_jog_and_homing_lock_out_gcode_but_not_system_commands() {
    let mut g = GcodeState::new();
    refused_in(&mut g, "G0 X1", RunState::Alarm, 9);
    refused_in(&mut g, "G0 X1", RunState::Jog, 9);
    refused_in(&mut g, "G0 X1", RunState::Home, 9);
    refused_in(&mut g, "$O R5", RunState::Home, 9);
    refused_in(&mut g, "$J=G91 X1 F100", RunState::Home, 8);
    refused_in(&mut g, "$O R5", RunState::Alarm, 9);
    refused_in(&mut g, "$F X0 U1 Y=x", RunState::Alarm, 9);
    refused_in(&mut g, "$J=G91 X1 F100", RunState::Alarm, 8);
    refused_in(&mut g, "$J=G91 X1 F100", RunState::Run, 8);
    // A setting behind a running program waits for it (the host link holds it until rest).
    assert_eq!(run_in(&mut g, "$100=80", RunState::Run), Ok(std::vec![Command::SetSetting { id: 100, value: 80.0 }]));
    refused_in(&mut g, "$100=80", RunState::Hold, 8);
    refused_in(&mut g, "$100=80", RunState::Jog, 8);
    refused_in(&mut g, "$RST=$", RunState::Hold, 8);
    assert_eq!(run_in(&mut g, "$X", RunState::Alarm), Ok(std::vec![Command::Unlock]));
    assert_eq!(run_in(&mut g, "$$", RunState::Alarm), Ok(std::vec![Command::Report(Report::Settings)]));
    assert_eq!(run_in(&mut g, "$100=80", RunState::Alarm), Ok(std::vec![Command::SetSetting { id: 100, value: 80.0 }]));
    // Streaming continues while a job runs or is held.
    let from = g.planned_position();
    assert_eq!(
        run_in(&mut g, "G0 X1", RunState::Hold),
        Ok(std::vec![line_from(from, 100, 0, Feed::Rapid, JobKind::Draw)])
    );
}

#[test]
fn system_commands() {
    let mut g = GcodeState::new();
    let report = |r| Ok(std::vec![Command::Report(r)]);
    assert_eq!(run(&mut g, "$"), report(Report::Help));
    assert_eq!(run(&mut g, "$$"), report(Report::Settings));
    assert_eq!(run(&mut g, "  $g"), report(Report::ParserState));
    assert_eq!(run(&mut g, "$#"), report(Report::Parameters));
    assert_eq!(run(&mut g, "$I"), report(Report::BuildInfo));
    assert_eq!(run(&mut g, "$x"), Ok(std::vec![Command::Unlock]));
    refused(&mut g, "$H", 5);
    assert_eq!(run(&mut g, "$C"), Ok(std::vec![Command::CheckMode { on: true }]));
    assert_eq!(run_in(&mut g, "$C", RunState::Check), Ok(std::vec![Command::CheckMode { on: false }]));
    refused_in(&mut g, "$C", RunState::Run, 8);
    assert_eq!(run(&mut g, "$SLP"), Ok(std::vec![Command::Sleep]));
    // Behind a running program, the sleep waits for it; held or jogging, it is refused.
    assert_eq!(run_in(&mut g, "$SLP", RunState::Run), Ok(std::vec![Command::Sleep]));
    refused_in(&mut g, "$SLP", RunState::Hold, 8);
    refused_in(&mut g, "$SLP", RunState::Jog, 8);
    refused(&mut g, "$N2=G20", 3);
    refused(&mut g, "$Q", 3);
    refused(&mut g, "$GX", 3);
    refused(&mut g, "$RST=x", 3);
}
