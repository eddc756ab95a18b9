//! How the line loop carries out the card's turns (see `card_plot` for the file's session): the
//! resume record looked for at power-on, the check of the chosen file a bounded piece at a time,
//! the user's answers, and the plot's moves and lines, each carried out by the one parser as a
//! host link's line is.

use embassy_futures::select::select;
use embassy_futures::yield_now;
use embassy_time::{Duration, Instant, Timer};
use embedded_storage::nor_flash::NorFlash;

use super::card_plot::{self, CardPlot, CardRoom, CardSession, CardStep, CardTurn, US_PER_MS, end};
use super::{Host, Parser, Unfinished};
use crate::card::keeper::{LineMark, RESUME_STORE_MIN_MS, ResumeKeeper};
use crate::card::{CardError, CardFacts, CardFile, CardLine, CardLines, CardPicture, CardProgress, CardSlot, CardStop};
use crate::host::gcode::{GcodeState, Spindle};
use crate::machine_io::pen::Pen;
use crate::motion::job::Control;
use crate::program::check::Progress;
use crate::program::preview::StrokeMap;
use crate::tasks::slices::BetweenSlices;

impl CardSession {
    /// The card's turn: the file the keypad chooses while none is; the user's answer once a
    /// file is checked or a resume offered; at once at power-on, while a file is being checked
    /// or has lines to send; once the machine rests after its last line (the plot lasts until
    /// then), or a record's time later.
    pub async fn turn(&self, host: &Host<'_>, slot: &CardSlot<'_>) -> CardTurn {
        match self {
            CardSession::Idle => return CardTurn::Chosen(slot.plot_requested().await),
            CardSession::Checked { .. } | CardSession::Offered { .. } => {
                return CardTurn::Answer(slot.answered().await);
            }
            CardSession::Plotting(p) if p.sent_all() => {
                let keep = Timer::after(Duration::from_millis(RESUME_STORE_MIN_MS));
                let _rest_or_time = select(host.machine_at_rest(), keep).await;
            }
            CardSession::PowerOn | CardSession::Checking { .. } | CardSession::Plotting(_) => {}
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
            (CardTurn::Step, CardSession::PowerOn) => offer(slot),
            (CardTurn::Chosen(file), _) => self.check_start(slot, file, room),
            (CardTurn::Answer(true), CardSession::Offered { file, record }) => {
                self.host.card_abort.set(false);
                self.host.card_line.set(Some(0));
                self.plan = self.host.machine.plan_end();
                match CardPlot::resume(slot, room.keeper, file, record, &self.host.machine.settings()) {
                    Some(plot) => CardSession::Plotting(plot),
                    None => {
                        self.card_end(slot);
                        CardSession::Idle
                    }
                }
            }
            (CardTurn::Answer(false), CardSession::Offered { .. }) => {
                info!("card: resume dropped");
                self.plot_over(slot, room.keeper);
                CardSession::Idle
            }
            // A reset on a host link while the file was shown leaves it.
            (CardTurn::Answer(true), CardSession::Checked { file, facts }) if !self.host.card_abort.take() => {
                let at = self.plan.map_or(self.host.machine.position(), |end| end.at());
                match CardPlot::start(slot, room.keeper, file, facts.lines, at, self.gcode.modal()) {
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
                let goes_on = self.card_step(slot, plot, room.keeper).await;
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

    /// Carries out the card plot's next move or line, as a line of a host link, and hands the
    /// plot its answer; an abort since the line before ends the plot. Keeps the resume record
    /// when it is due. True while the plot goes on.
    async fn card_step(&mut self, slot: &CardSlot<'_>, plot: &mut CardPlot, keeper: &mut ResumeKeeper) -> bool {
        let host = self.host;
        let aborted = slot.take_abort() | host.card_abort.take() || host.machine.plan_end() != self.plan;
        if plot.sent_all() && !aborted && !host.machine.at_rest() {
            // The last lines still run: their record is kept meanwhile.
            card_plot::keep(slot, keeper, host.machine.emitted_totals().0, Instant::now().as_millis());
            return true;
        }
        let (resume_line, _, _) = plot.place();
        let (number, result) = match plot.next(slot) {
            CardStep::Move(text) if !aborted => return self.resume_move(slot, keeper, resume_line, text).await,
            CardStep::Travel if !aborted => {
                let text = card_plot::travel_line(keeper.record_at().0, &host.machine.settings());
                return self.resume_move(slot, keeper, resume_line, &text).await;
            }
            CardStep::PenDown if !aborted => {
                let text = if keeper.record_at().1.spindle == Spindle::Ccw { "M4" } else { "M3" };
                return self.resume_move(slot, keeper, resume_line, text).await;
            }
            CardStep::Restore if !aborted => {
                self.restore(keeper);
                return true;
            }
            CardStep::Begin if !aborted => {
                drop(host.machine_at_rest().await);
                keeper.begin(self.handed_steps, host.machine.emitted_totals().0);
                return true;
            }
            CardStep::Line { number, text } if !aborted => {
                host.card_line.set(Some(number));
                (number, self.card_line(text).await)
            }
            CardStep::Refused { number, error } if !aborted => (number, Err(Unfinished::Error(error))),
            CardStep::SentAll => return true,
            CardStep::Lost(e) if !aborted => {
                self.card_lost(slot, e).await;
                return false;
            }
            _ => return self.plot_over(slot, keeper),
        };
        let refused = match result {
            Ok(()) => None,
            // Not refused by an abort that came while it waited: that ends the plot silently.
            Err(Unfinished::Error(e)) if host.machine.plan_end() == self.plan || self.plan.is_none() => Some(e),
            Err(_) => return self.plot_over(slot, keeper),
        };
        if !plot.answered(slot, number, refused) {
            return self.plot_over(slot, keeper);
        }
        self.line_done(slot, plot, keeper);
        true
    }

    /// The plot's line was answered `ok`: marked for the resume record, which is stored if due.
    /// Out of line: the mark and the record are temporaries of this frame only.
    #[inline(never)]
    fn line_done(&self, slot: &CardSlot<'_>, plot: &CardPlot, keeper: &mut ResumeKeeper) {
        let emitted = self.host.machine.emitted_totals().0;
        if let Some(end) = self.plan {
            let (next_line, offset, after_cr) = plot.place();
            let modal = self.gcode.modal();
            let handed_steps = self.handed_steps;
            keeper.answered(LineMark { next_line, offset, after_cr, handed_steps, position: end.at(), modal }, emitted);
        }
        card_plot::keep(slot, keeper, emitted, Instant::now().as_millis());
    }

    /// A move of the resume's own (`text`), before the file's lines from `resume_line`: true if
    /// the plot goes on. One refused leaves the record for another try.
    async fn resume_move(
        &mut self,
        slot: &CardSlot<'_>,
        keeper: &mut ResumeKeeper,
        resume_line: u32,
        text: &str,
    ) -> bool {
        match self.card_line(text).await {
            Ok(()) => {
                // Homing moved the plan's end: the next step starts from there.
                self.plan = self.host.machine.plan_end();
                true
            }
            Err(Unfinished::Error(error)) => {
                self.card_end(slot);
                slot.stopped(CardStop::Refused { line: resume_line, error });
                false
            }
            Err(_) => self.plot_over(slot, keeper),
        }
    }

    /// The parser's state is the one the plot goes on with, planned from where the plan ends
    /// (the resume's rapid took the pen there).
    #[inline(never)]
    fn restore(&mut self, keeper: &ResumeKeeper) {
        let at = self.plan.map_or(self.host.machine.position(), |end| end.at());
        self.gcode = GcodeState::resumed(&keeper.record_at().1, at, &self.host.machine.settings());
    }

    /// Carries out a line of the card plot (of its file, or a move of its own), as a line of a
    /// host link.
    async fn card_line(&mut self, text: &str) -> Result<(), Unfinished> {
        let host = self.host;
        let result = match self.line(&host.card, text).await {
            Ok(()) => self.keep(&host.card).await,
            refused => refused,
        };
        if core::mem::take(&mut self.restart_after_answer) {
            self.restart(&host.card).await;
        }
        result
    }

    /// The plot is over as meant (its last line, a refusal, an abort): its resume record is
    /// cleared, and host lines are taken again. False: the plot does not go on.
    fn plot_over(&mut self, slot: &CardSlot<'_>, keeper: &mut ResumeKeeper) -> bool {
        card_plot::clear(slot, keeper);
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

/// At power-on: the plot a power cut stopped, offered if the card keeps one whose file is there.
#[inline(never)]
fn offer(slot: &CardSlot<'_>) -> CardSession {
    match slot.with(|card| card.load_resume()) {
        Ok(Some(record)) => match card_plot::offer(slot, &record) {
            Some(file) => CardSession::Offered { file, record },
            None => CardSession::Idle,
        },
        Ok(None) | Err(CardError::NoCard) => CardSession::Idle,
        Err(e) => {
            warn!("card: no resume record read: {}", e.message());
            CardSession::Idle
        }
    }
}
