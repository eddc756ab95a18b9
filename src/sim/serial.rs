//! The simulated host link: bytes in from a file or standard input, answers out to a buffer
//! (and optionally standard output), through the same embedded-io traits as the UART.
//!
//! Input known in advance is streamed the way GRBL senders stream ("send-response"): the next line
//! goes out once the firmware has answered the previous one with `ok` or `error:N`. Live standard
//! input is passed on as typed, and so is what a sender writes to the pseudo-terminal of
//! [`SimSerial::from_pty`], which gets the answers back. Bytes wait here until the firmware reads
//! them, as a USB port holds back its host's writes (the most that waited is kept,
//! [`SimSerial::most_unread`]); on the UART the firmware reads on, and drops what finds no room.
//! A link can also be opened and closed by its host at given times, as a sender opens and closes
//! a USB serial port (DTR set and cleared): the read after the bytes sent before then reports the
//! change, as the board's USB port does.

use core::future::poll_fn;
use core::task::{Poll, Waker};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::io::Write as _;
use std::rc::Rc;
use std::sync::mpsc;
use std::vec::Vec;

use crate::tasks::serial::{PORT_CLOSED, PORT_OPENED};

/// What the host did to the port.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortChange {
    /// Opened it: DTR set.
    Opened,
    /// Closed it: DTR cleared.
    Closed,
}
use crate::sim::pty::Pty;

/// Most bytes taken from a live source at once.
const LIVE_READ_BYTES: usize = 256;

#[derive(Default)]
struct Link {
    input: VecDeque<u8>,
    /// Lines not yet sent, for paced input.
    unsent: VecDeque<Vec<u8>>,
    /// Bytes sent at given virtual times, in order (a person pressing `!` mid-drawing).
    timed: VecDeque<(u64, u8)>,
    /// Virtual times the host opens or closes the port, in order.
    changes: VecDeque<(u64, PortChange)>,
    /// Changes made, each after this many input bytes in all; not read yet.
    changed: VecDeque<(usize, PortChange)>,
    /// Input bytes sent in all, and read by the firmware in all.
    sent: usize,
    read: usize,
    /// The most input bytes ever waiting to be read.
    most_unread: usize,
    /// A reset (0x18) went out and its banner has not come back yet.
    reset_sent: bool,
    /// Answers (`ok` / `error:`) still owed for lines sent.
    owed: usize,
    /// The output seen so far that does not end in a line end yet.
    partial: Vec<u8>,
    /// Every whole line of output (without its line end), with the virtual time it ended.
    lines: Vec<(u64, std::string::String)>,
    /// Standard input or the pseudo-terminal, read by a thread of its own, when the simulator is
    /// driven live.
    live: Option<mpsc::Receiver<Vec<u8>>>,
    /// The pseudo-terminal the answers go to, when a sender drives the link through one.
    port: Option<Pty>,
    live_ended: bool,
    reader: Option<Waker>,
    output: Vec<u8>,
    echo_stdout: bool,
}

/// Both ends of the simulated serial link.
#[derive(Clone, Default)]
pub struct SimSerial {
    link: Rc<RefCell<Link>>,
}

impl SimSerial {
    /// A link whose whole input is known in advance (a file, a test transcript), streamed a
    /// line at a time as each previous line is answered.
    pub fn with_input(bytes: &[u8]) -> Self {
        let s = SimSerial::default();
        {
            let mut l = s.link.borrow_mut();
            l.unsent = bytes.split_inclusive(|b| *b == b'\n').map(<[u8]>::to_vec).collect();
            l.send_next_line();
        }
        s
    }

    /// A link fed live from standard input.
    pub fn from_stdin() -> Self {
        Self::live(std::io::stdin())
    }

    /// A link fed live by whatever sender opens the pseudo-terminal's port, and answering it
    /// there.
    pub fn from_pty(pty: Pty) -> std::io::Result<Self> {
        let s = Self::live(pty.reader()?);
        s.link.borrow_mut().port = Some(pty);
        Ok(s)
    }

    /// A link fed live from `source`, read as it sends, until it ends.
    fn live(mut source: impl std::io::Read + Send + 'static) -> Self {
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut buf = [0u8; LIVE_READ_BYTES];
            while let Ok(n @ 1..) = source.read(&mut buf) {
                if tx.send(buf[..n].to_vec()).is_err() {
                    break;
                }
            }
        });
        let s = SimSerial::default();
        s.link.borrow_mut().live = Some(rx);
        s
    }

    /// Also sends `byte` at virtual time `t_us` (a realtime command such as `!` or `~`).
    pub fn with_byte_at(self, t_us: u64, byte: u8) -> Self {
        {
            let mut l = self.link.borrow_mut();
            let i = l.timed.partition_point(|(t, _)| *t <= t_us);
            l.timed.insert(i, (t_us, byte));
        }
        self
    }

    /// Also closes the port at virtual time `t_us`, after the bytes sent before then.
    pub fn with_closing_at(self, t_us: u64) -> Self {
        self.with_change_at(t_us, PortChange::Closed)
    }

    /// Also opens the port (raises DTR) at virtual time `t_us`, after the bytes sent before then,
    /// as a sender does when it opens the USB port. The port counts as open from the start.
    pub fn with_opening_at(self, t_us: u64) -> Self {
        self.with_change_at(t_us, PortChange::Opened)
    }

    fn with_change_at(self, t_us: u64, change: PortChange) -> Self {
        {
            let mut l = self.link.borrow_mut();
            let i = l.changes.partition_point(|(t, _)| *t <= t_us);
            l.changes.insert(i, (t_us, change));
        }
        self
    }

    /// When the next timed byte or change of the port is due.
    pub fn next_timed_us(&self) -> Option<u64> {
        let l = self.link.borrow();
        let byte = l.timed.front().map(|(t, _)| *t);
        let change = l.changes.front().map(|(t, _)| *t);
        byte.into_iter().chain(change).min()
    }

    /// Sends the timed bytes due by now, and opens or closes the port if that is due; in time
    /// order.
    pub fn deliver_due(&self) {
        let now = crate::sim::clock::now_ticks();
        let mut l = self.link.borrow_mut();
        let mut sent = false;
        loop {
            let byte_at = l.timed.front().map(|(t, _)| *t).filter(|t| *t <= now);
            let change_at = l.changes.front().map(|(t, _)| *t).filter(|t| *t <= now);
            let change_first = match (byte_at, change_at) {
                (None, None) => break,
                // Bytes sent at the time of a change go before it.
                (Some(tb), Some(tc)) => tc < tb,
                (Some(_), None) => false,
                (None, Some(_)) => true,
            };
            if change_first {
                if let Some((_, change)) = l.changes.pop_front() {
                    let after = l.sent;
                    l.changed.push_back((after, change));
                    if change == PortChange::Closed {
                        // The sender is gone: it waits for no answer any more.
                        l.owed = 0;
                    }
                }
            } else if let Some((_, b)) = l.timed.pop_front() {
                l.push_input(core::iter::once(b));
                l.reset_sent |= b == 0x18;
            }
            sent = true;
        }
        if sent && let Some(w) = l.reader.take() {
            w.wake();
        }
    }

    /// The most bytes the host ever had sent that the firmware had not read yet.
    pub fn most_unread(&self) -> usize {
        self.link.borrow().most_unread
    }

    /// Also print every answer on standard output as it is written.
    pub fn echo_to_stdout(self) -> Self {
        self.link.borrow_mut().echo_stdout = true;
        self
    }

    /// Everything the firmware wrote so far.
    pub fn output(&self) -> Vec<u8> {
        self.link.borrow().output.clone()
    }

    /// Every whole line the firmware wrote so far, with the virtual time, µs, it was written.
    pub fn timed_lines(&self) -> Vec<(u64, std::string::String)> {
        self.link.borrow().lines.clone()
    }

    /// True when no input is waiting, none can come any more, and every paced line has had its
    /// answer (a last `G4` answers only once its dwell is over).
    pub fn input_done(&self) -> bool {
        let l = self.link.borrow();
        l.input.is_empty()
            && l.unsent.is_empty()
            && l.owed == 0
            && l.timed.is_empty()
            && l.changes.is_empty()
            && l.changed.is_empty()
            && (l.live.is_none() || l.live_ended)
    }

    /// Takes what standard input has sent, waiting for it up to `wait` of real time.
    /// Returns false once standard input has ended.
    pub fn pump_live(&self, wait: std::time::Duration) -> bool {
        let mut l = self.link.borrow_mut();
        let Some(rx) = l.live.take() else { return false };
        let got = if wait.is_zero() {
            rx.try_recv()
        } else {
            rx.recv_timeout(wait).map_err(|e| match e {
                mpsc::RecvTimeoutError::Timeout => mpsc::TryRecvError::Empty,
                mpsc::RecvTimeoutError::Disconnected => mpsc::TryRecvError::Disconnected,
            })
        };
        match got {
            Ok(bytes) => {
                l.push_input(bytes);
                l.live = Some(rx);
                if let Some(w) = l.reader.take() {
                    w.wake();
                }
            }
            Err(mpsc::TryRecvError::Empty) => l.live = Some(rx),
            Err(mpsc::TryRecvError::Disconnected) => l.live_ended = true,
        }
        !l.live_ended
    }

    /// True while standard input may still send something.
    pub fn is_live(&self) -> bool {
        let l = self.link.borrow();
        l.live.is_some() && !l.live_ended
    }
}

impl Link {
    /// The host sends `bytes`.
    fn push_input(&mut self, bytes: impl IntoIterator<Item = u8>) {
        let before = self.input.len();
        self.input.extend(bytes);
        self.sent += self.input.len() - before;
        self.most_unread = self.most_unread.max(self.input.len());
    }

    /// Sends the next paced line, if no answer is owed.
    fn send_next_line(&mut self) {
        if self.owed > 0 {
            return;
        }
        if let Some(line) = self.unsent.pop_front() {
            // Realtime bytes get no answer; only a line end asks for one.
            if line.ends_with(b"\n") {
                self.owed += 1;
            }
            self.push_input(line);
            if let Some(w) = self.reader.take() {
                w.wake();
            }
        }
    }

    /// Notes the answers in what the firmware wrote and releases the next line.
    fn heard(&mut self, bytes: &[u8]) {
        for &b in bytes {
            if b == b'\n' {
                let line = core::mem::take(&mut self.partial);
                let text = std::string::String::from_utf8_lossy(&line);
                self.lines.push((crate::sim::clock::now_ticks(), text.trim_end_matches('\r').into()));
                if line.starts_with(b"ok") || line.starts_with(b"error:") {
                    self.owed = self.owed.saturating_sub(1);
                } else if line.starts_with(b"Grbl ") && self.reset_sent {
                    // The banner after a reset we sent: as a sender does, stop streaming; lines
                    // in flight get no answer.
                    self.reset_sent = false;
                    self.owed = 0;
                    self.unsent.clear();
                }
            } else {
                self.partial.push(b);
            }
        }
        self.send_next_line();
    }
}

/// The host opened or closed the port: the one way a read of the simulated link ends without
/// bytes, reported as the board's USB port reports it.
#[derive(Debug)]
pub struct PortChanged(pub PortChange);

impl core::fmt::Display for PortChanged {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self.0 {
            PortChange::Opened => "port opened",
            PortChange::Closed => "port closed",
        })
    }
}

impl core::error::Error for PortChanged {}

impl embedded_io_async::Error for PortChanged {
    fn kind(&self) -> embedded_io_async::ErrorKind {
        match self.0 {
            PortChange::Opened => PORT_OPENED,
            PortChange::Closed => PORT_CLOSED,
        }
    }
}

impl embedded_io_async::ErrorType for SimSerial {
    type Error = PortChanged;
}

impl embedded_io_async::Read for SimSerial {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        poll_fn(|cx| {
            let mut l = self.link.borrow_mut();
            let next_change = l.changed.front().copied();
            if let Some((after, change)) = next_change
                && after == l.read
            {
                l.changed.pop_front();
                return Poll::Ready(Err(PortChanged(change)));
            }
            if l.input.is_empty() {
                // A UART with nothing received simply waits; it never reports an end.
                l.reader = Some(cx.waker().clone());
                return Poll::Pending;
            }
            let before_change = next_change.map_or(usize::MAX, |(after, _)| after - l.read);
            let n = buf.len().min(l.input.len()).min(before_change);
            l.read += n;
            for (dst, src) in buf.iter_mut().zip(l.input.drain(..n)) {
                *dst = src;
            }
            Poll::Ready(Ok(n))
        })
        .await
    }
}

impl embedded_io_async::Write for SimSerial {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        let mut l = self.link.borrow_mut();
        l.output.extend_from_slice(buf);
        l.heard(buf);
        if let Some(port) = l.port.as_mut() {
            port.send(buf);
        }
        if l.echo_stdout {
            let mut out = std::io::stdout().lock();
            let _ = out.write_all(buf);
            let _ = out.flush();
        }
        Ok(buf.len())
    }

    async fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}
