//! How the line loop carries out the card's turns (see `card_plot` for the file's session): the
//! check of the chosen file a bounded piece at a time, the user's answer, and the plot's lines,
//! each carried out by the one parser as a host link's line is.

use embassy_futures::yield_now;
use embedded_storage::nor_flash::NorFlash;

use super::card_plot::{CardPlot, CardRoom, CardSession, CardStep, CardTurn, US_PER_MS, end};
use super::{Host, Parser, Unfinished};
use crate::card::{CardError, CardFacts, CardFile, CardLine, CardLines, CardPicture, CardProgress, CardSlot, CardStop};
use crate::machine_io::pen::Pen;
use crate::motion::job::Control;
use crate::program::check::Progress;
use crate::program::preview::StrokeMap;
use crate::tasks::slices::BetweenSlices;

impl CardSession {
    /// The card's turn: the file the keypad chooses while none is; the user's answer once it is
    /// checked; at once while it is being checked or has lines to send; once the machine rests
    /// after its last line (the plot lasts until then).
    pub async fn turn(&self, host: &Host<'_>, slot: &CardSlot<'_>) -> CardTurn {
        match self {
            CardSession::Idle => return CardTurn::Chosen(slot.plot_requested().await),
            CardSession::Checked { .. } => return CardTurn::Answer(slot.answered().await),
            CardSession::Plotting(p) if p.sent_all() => drop(host.machine_at_rest().await),
            CardSession::Checking { .. } | CardSession::Plotting(_) => {}
        }
        CardTurn::Step
    }
}

impl<F: NorFlash, B: BetweenSlices> Parser<'_, '_, F, B> {
    /// Carries out the card's turn.
    pub(super) async fn card_turn(
        &mut self,
        turn: CardTurn,
        slot: &CardSlot<'_>,
        room: &mut CardRoom<'_, '_>,
        session: &mut CardSession,
    ) {
        let next = match (turn, &mut *session) {
            (CardTurn::Chosen(file), _) => self.check_start(slot, file, room),
            // A reset on a host link while the file was shown leaves it.
            (CardTurn::Answer(true), CardSession::Checked { file, facts }) if !self.host.card_abort.take() => {
                match CardPlot::start(slot, file, facts.lines) {
                    Some(plot) => CardSession::Plotting(plot),
                    None => {
                        self.card_end(slot);
                        CardSession::Idle
                    }
                }
            }
            (CardTurn::Answer(_), _) => {
                info!("card: file left");
                self.card_end(slot);
                CardSession::Idle
            }
            (CardTurn::Step, CardSession::Checking { file, lines, line }) => {
                let over = self.check_step(slot, room, lines, line);
                yield_now().await;
                match over {
                    None => return,
                    Some(Ok(facts)) => {
                        info!("card file checked: {} lines, {} ms", facts.lines, facts.plot_time_ms);
                        slot.set_progress(CardProgress::Checked(facts));
                        CardSession::Checked { file: file.clone(), facts }
                    }
                    Some(Err(stop)) => {
                        self.card_end(slot);
                        if let Some(stop) = stop {
                            slot.stopped(stop);
                        }
                        CardSession::Idle
                    }
                }
            }
            (CardTurn::Step, CardSession::Plotting(plot)) => {
                let goes_on = self.card_step(slot, plot).await;
                // A line that queued without waiting leaves the loop ready at once for the next:
                // the other tasks run between two lines, as between two pieces of the check.
                yield_now().await;
                if goes_on {
                    return;
                }
                CardSession::Idle
            }
            (CardTurn::Step, _) => return,
        };
        *session = next;
    }

    /// The check of `file` begins, from where the plan ends, with the machine's settings and
    /// pen; host lines are refused from now on.
    fn check_start(&mut self, slot: &CardSlot<'_>, file: CardFile, room: &mut CardRoom<'_, '_>) -> CardSession {
        info!("card: checking {}", file.name.as_str());
        let machine = &self.host.machine;
        if let Err(e) = slot.with(|card| card.open(&file)) {
            self.card_end(slot);
            slot.stopped(CardStop::Card(e));
            return CardSession::Idle;
        }
        let settings = machine.settings();
        let mut gcode = self.gcode;
        self.plan = machine.plan_end();
        if let Some(end) = self.plan {
            gcode.plan_from(end.at(), &settings);
        }
        room.check.start(gcode, &settings, machine.pen(), room.planner);
        *slot.picture_mut() =
            Some(CardPicture { scale: *room.check.scale(), strokes: StrokeMap::new(), progress: None });
        let _before = slot.take_abort();
        slot.set_progress(CardProgress::Checking { lines: 0 });
        self.host.card_abort.set(false);
        self.host.card_line.set(Some(0));
        CardSession::Checking { file, lines: CardLines::new(), line: 0 }
    }

    /// One bounded piece of the check: the next line read and parsed, or a piece of its work.
    /// `Some` once it is over: what it found, or why the file is refused (`None`: the user left
    /// it, or a reset came).
    fn check_step(
        &mut self,
        slot: &CardSlot<'_>,
        room: &mut CardRoom<'_, '_>,
        lines: &mut CardLines,
        line: &mut u32,
    ) -> Option<Result<CardFacts, Option<CardStop>>> {
        if slot.take_abort() | self.host.card_abort.take() {
            info!("card: check left");
            return Some(Err(None));
        }
        let refused = |stop| Some(Err(Some(stop)));
        match room.check.work(room.planner) {
            Progress::Working => None,
            Progress::Ready => match slot.with(|card| lines.next(card)) {
                Ok(CardLine::Line { number, text }) => {
                    *line = number;
                    room.check.push_line(text);
                    slot.set_progress(CardProgress::Checking { lines: number });
                    None
                }
                Ok(CardLine::Refused { number, error }) => refused(CardStop::Refused { line: number, error }),
                Ok(CardLine::End) => {
                    room.check.end();
                    None
                }
                Err(e) => refused(CardStop::Card(e)),
            },
            Progress::Refused(refusal) => refused(CardStop::Refused { line: *line, error: refusal.error }),
            Progress::Done => {
                if let Some(picture) = slot.picture_mut().as_mut() {
                    picture.strokes = room.check.strokes_map().clone();
                }
                // Every drawing was built within the travel: a line leaving it was refused.
                let summary = room.check.summary();
                let size_mm = summary.strokes_size_mm(room.check.settings()).unwrap_or([0.0; 2]);
                let plot_time_ms = u32::try_from(summary.plot_time_us / US_PER_MS).unwrap_or(u32::MAX);
                let steps = u32::try_from(summary.steps).unwrap_or(u32::MAX);
                Some(Ok(CardFacts { lines: lines.lines_done(), size_mm, plot_time_ms, steps }))
            }
        }
    }

    /// Carries out the card plot's next line, as a line of a host link, and hands the plot its
    /// answer; an abort since the line before ends the plot. True while the plot goes on.
    async fn card_step(&mut self, slot: &CardSlot<'_>, plot: &mut CardPlot) -> bool {
        let host = self.host;
        let aborted = slot.take_abort() | host.card_abort.take() || host.machine.plan_end() != self.plan;
        let (number, result) = match plot.next(slot) {
            CardStep::Line { number, text } if !aborted => {
                host.card_line.set(Some(number));
                match self.line(&host.card, text).await {
                    Ok(()) => (number, self.keep(&host.card).await),
                    refused => (number, refused),
                }
            }
            CardStep::Refused { number, error } if !aborted => (number, Err(Unfinished::Error(error))),
            CardStep::SentAll => return true,
            CardStep::Lost(e) if !aborted => {
                self.card_lost(slot, e).await;
                return false;
            }
            _ => {
                self.card_end(slot);
                return false;
            }
        };
        if core::mem::take(&mut self.restart_after_answer) {
            self.restart(&host.card).await;
        }
        let refused = match result {
            Ok(()) => None,
            // Not refused by an abort that came while it waited: that ends the plot silently.
            Err(Unfinished::Error(e)) if host.machine.plan_end() == self.plan || self.plan.is_none() => Some(e),
            Err(_) => {
                self.card_end(slot);
                return false;
            }
        };
        if plot.answered(slot, number, refused) {
            return true;
        }
        self.card_end(slot);
        false
    }

    /// The card failed before the plot's last line was sent: what is queued would end the plot
    /// at some point of the file no one chose. So the pen stops on its path (an abort: a
    /// controlled stop, the position exact), the lines queued behind are dropped, the pen goes
    /// up, and the machine is in an alarm until `$X`; the LCD and the log say why.
    async fn card_lost(&mut self, slot: &CardSlot<'_>, e: CardError) {
        let host = self.host;
        host.machine.request(Control::Abort);
        drop(host.machine_stopped().await);
        host.machine.set_pen(Pen::Up);
        host.machine.card_lost();
        self.card_end(slot);
        slot.stopped(CardStop::Card(e));
    }

    /// The card's file is done with: host lines are taken again.
    fn card_end(&mut self, slot: &CardSlot<'_>) {
        end(slot);
        self.host.card_line.set(None);
    }
}
