//! One host link as the serial task sees it: the pipe of line bytes from its receiver to the line
//! loop, what the receiver does when the pipe is full (its [`Flow`]), its outbox of whole answers
//! to its writer, and what a reset or a closing of the port leaves for the line loop to do.
//! Nothing here knows the link's port: only [`write_answers`] touches it, and the receiver's
//! reads live with the protocol.

use core::cell::Cell;

use core::future::Future;

use embassy_futures::select::{Either, select, select_array};
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::pipe::Pipe;
use embassy_sync::signal::Signal;
use embassy_time::{Duration, Timer};
use embedded_io_async::Write;
use heapless::String;

use super::dropped::Dropped;
use crate::host::report::{self, Reply};

/// Bytes between a link's receiver and the line loop. GRBL senders keep at most 128 unanswered
/// bytes in flight, so this never fills for them; it also holds a terminal paste of about 50
/// lines beyond what the machine has room for. Beyond that, see [`Flow`].
pub const SERIAL_PIPE_BYTES: usize = 1024;
/// What a sender may assume it can have in flight (reported by `$I` and `Bf:`).
pub const SERIAL_RX_WINDOW_BYTES: usize = 128;
/// Longest answer to one line: `$$` lists every setting (about 300 bytes).
pub const SERIAL_ANSWER_MAX_BYTES: usize = 512;
/// Whole answers waiting for a link's writer, beyond the one it is writing.
pub const SERIAL_OUTBOX_ANSWERS: usize = 1;
/// On a link whose port does not hold its host back ([`Flow::Dropping`]), how long a byte may
/// wait for room in the pipe before it is dropped: the line loop drains the pipe far faster
/// unless it is waiting for the machine.
pub const SERIAL_PIPE_WAIT_MS: u64 = 20;
/// Bytes taken from a port, or from a pipe, at a time.
pub const SERIAL_CHUNK_BYTES: usize = 32;

/// In the pipe, where a reset came: the reset byte itself. Line bytes are never realtime bytes,
/// so it cannot be mistaken for one.
pub const RESET_MARK: u8 = 0x18;
/// In the pipe, where the host closed the port: the line under way there can never end. Any
/// realtime byte would do, as for [`RESET_MARK`] (the receiver acts on realtime bytes and never
/// passes them on): this is GRBL's safety door byte.
pub const CLOSED_MARK: u8 = 0x84;

/// One answer, written to its link as a whole.
pub type Answer = String<SERIAL_ANSWER_MAX_BYTES>;

/// What a link's receiver does with a line byte that finds the pipe full.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// The port has no flow control (a UART without handshake lines): the host's bytes keep
    /// arriving, so after `SERIAL_PIPE_WAIT_MS` the byte is dropped, and its line with it, rather
    /// than holding up the realtime bytes behind it; see the serial task's documentation.
    Dropping,
    /// The port holds the host back while the receiver does not read (USB CDC-ACM: the device
    /// takes the next packet only once the last is read, and the host's write waits): the
    /// receiver waits for room, and no byte is ever dropped.
    Waiting,
}

/// What the line loop has to do next on a link.
pub enum Intake {
    /// `n` bytes arrived, in the buffer given to [`Link::intake`].
    Bytes(usize),
    /// Lines dropped for want of room in the pipe, to answer `error:100` each.
    Dropped(u32),
}

/// One host link's state, shared by its receiver, its writer and the line loop; all run on one
/// executor, so plain cells do.
pub struct Link {
    flow: Cell<Flow>,
    outbox: Channel<NoopRawMutex, Answer, SERIAL_OUTBOX_ANSWERS>,
    bytes: Pipe<NoopRawMutex, SERIAL_PIPE_BYTES>,
    /// Lines dropped for want of room in the pipe; see the serial task's documentation.
    dropped: Dropped,
    /// Resets received and not yet met by the line loop: bytes before them are dropped.
    resets_pending: Cell<u32>,
    /// Cancels a line of this link waiting for the machine when a reset arrives.
    reset: Signal<NoopRawMutex, ()>,
}

impl Link {
    /// A link whose receiver drops what finds no room ([`Flow::Dropping`]) until
    /// [`set_flow`](Self::set_flow) says otherwise. (Built without arguments, the two links of
    /// the host link are built straight into its future, not on the stack and moved.)
    pub fn new() -> Self {
        Link {
            flow: Cell::new(Flow::Dropping),
            outbox: Channel::new(),
            bytes: Pipe::new(),
            dropped: Dropped::default(),
            resets_pending: Cell::new(0),
            reset: Signal::new(),
        }
    }

    /// What the receiver does when the pipe is full: what the link's port allows.
    pub fn set_flow(&self, flow: Flow) {
        self.flow.set(flow);
    }

    /// Sends `reply` as one whole answer, once the outbox has room.
    pub fn send<'a>(&'a self, reply: Reply<'a>) -> Sending<'a> {
        Sending { link: self, reply }
    }

    /// Runs `work` unless a reset on this link comes first (or is already on its way).
    pub async fn unless_reset<T>(&self, work: impl Future<Output = T>) -> Option<T> {
        if self.resets_pending.get() > 0 {
            return None;
        }
        match select(work, self.reset.wait()).await {
            Either::First(t) => Some(t),
            Either::Second(()) => None,
        }
    }

    /// A reset arrived: the line waiting for the machine gives up, and the line loop drops
    /// every byte before the reset once it meets its mark.
    pub async fn reset_received(&self) {
        self.resets_pending.set(self.resets_pending.get() + 1);
        self.reset.signal(());
        self.dropped.clear();
        self.bytes.write_all(&[RESET_MARK]).await;
    }

    /// The line loop met a reset's mark and the machine has stopped: bytes after the mark count
    /// again, unless another reset follows.
    pub fn reset_met(&self) {
        self.resets_pending.set(self.resets_pending.get().saturating_sub(1));
        self.reset.reset();
    }

    /// True while a reset received has not been met by the line loop: bytes are dropped.
    pub fn resetting(&self) -> bool {
        self.resets_pending.get() > 0
    }

    /// The host closed the port: the line it was sending is cut off, and lines dropped before
    /// are owed to nobody.
    pub async fn closed(&self) {
        self.dropped.clear();
        self.bytes.write_all(&[CLOSED_MARK]).await;
    }

    /// Waits for the line loop's next work on this link: bytes read into `buf`, or dropped lines
    /// to answer once every byte before them is taken.
    pub async fn intake(&self, buf: &mut [u8]) -> Intake {
        loop {
            let dropped = self.dropped.take(self.bytes.is_empty());
            if dropped > 0 {
                return Intake::Dropped(dropped);
            }
            if let Either::First(n) = select(self.bytes.read(buf), self.dropped.counted.wait()).await {
                return Intake::Bytes(n);
            }
        }
    }

    /// Bytes of GRBL's receive window a sender may still send (`Bf:`): the window less what
    /// waits in the pipe.
    pub fn rx_window_free(&self) -> usize {
        SERIAL_RX_WINDOW_BYTES.saturating_sub(self.bytes.len())
    }

    /// Passes a byte of a line to the line loop, once the pipe has room for it. On a link
    /// [`Flow::Dropping`], when the pipe stays full for `SERIAL_PIPE_WAIT_MS` (a sender ignoring
    /// GRBL's flow control while the line loop waits for the machine) the byte is dropped rather
    /// than waited for, so realtime bytes behind it are still read, and its line with it; see the
    /// serial task's documentation.
    pub async fn line_byte(&self, byte: u8) {
        if self.flow.get() == Flow::Waiting {
            // Meanwhile the port takes nothing more from the host.
            self.bytes.write_all(&[byte]).await;
            return;
        }
        let d = &self.dropped;
        if !d.active.get() {
            let wait = Timer::after(Duration::from_millis(SERIAL_PIPE_WAIT_MS));
            if let Either::First(()) = select(self.bytes.write_all(&[byte]), wait).await {
                return;
            }
            d.active.set(true);
            self.send(Reply::Message(
                "Receive buffer full: lines dropped, each answered error:100; use a streaming sender",
            ))
            .await;
        }
        // CR and LF each end a line, as they do for the line assembler.
        if byte == b'\n' || byte == b'\r' {
            d.lines.set(d.lines.get() + 1);
            d.mid_line.set(false);
            d.counted.signal(());
        } else {
            d.mid_line.set(true);
        }
    }
}

/// The future of [`Link::send`]: it waits for room in the outbox, then writes the answer there.
/// One type with one `poll` out of line serves every answer, so a call site costs little more
/// than naming its reply.
pub struct Sending<'a> {
    link: &'a Link,
    reply: Reply<'a>,
}

impl Future for Sending<'_> {
    type Output = ();

    #[inline(never)]
    fn poll(self: core::pin::Pin<&mut Self>, cx: &mut core::task::Context<'_>) -> core::task::Poll<()> {
        let outbox = &self.link.outbox;
        if outbox.poll_ready_to_send(cx).is_pending() {
            return core::task::Poll::Pending;
        }
        let mut answer = Answer::new();
        if self.reply.write(&mut answer).is_err() {
            too_long(&mut answer);
        }
        // The room was seen just now: it is this answer's.
        if outbox.try_send(answer).is_err() {
            warn!("host link outbox full after waiting for room");
        }
        core::task::Poll::Ready(())
    }
}

/// Every answer fits by construction; should one not, it says so rather than being cut.
#[cold]
fn too_long(answer: &mut Answer) {
    answer.clear();
    let _ = report::message(answer, "answer too long");
}

/// The next work of either of two links for the line loop, and which link it is for, `first`
/// looked at first.
pub async fn intakes(links: &[Link; 2], bufs: &mut [[u8; SERIAL_CHUNK_BYTES]; 2], first: usize) -> (Intake, usize) {
    let [buf0, buf1] = bufs;
    let [link0, link1] = links;
    if first == 0 {
        select_array([link0.intake(buf0), link1.intake(buf1)]).await
    } else {
        let (intake, i) = select_array([link1.intake(buf1), link0.intake(buf0)]).await;
        (intake, 1 - i)
    }
}

/// Writes the link's answers to its port, each whole, in the order they were sent.
pub async fn write_answers<W: Write>(link: &Link, mut tx: W) -> ! {
    loop {
        let answer = link.outbox.receive().await;
        if tx.write_all(answer.as_bytes()).await.is_err() || tx.flush().await.is_err() {
            warn!("host link write failed");
        }
    }
}
