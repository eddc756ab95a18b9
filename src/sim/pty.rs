//! The simulated board's host link as a pseudo-terminal: a port any sender opens by its path
//! (`/dev/pts/N`), as it opens the USB-serial adapter of the board.
//!
//! The pair is put in raw mode (no echo, no line editing, bytes as sent: what a serial port
//! passes), and the simulator keeps the port's own end open too, so a sender may close it and
//! open it again. What the firmware writes while no one reads is dropped once the port's buffer
//! is full, as a UART's bytes are with nothing on the wire: the simulation never waits for a
//! sender.

use std::fs::File;
use std::io::{self, Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

/// Longest path of a pseudo-terminal's port.
const PTY_PATH_MAX_BYTES: usize = 128;

/// A pseudo-terminal pair: the simulator's end, and the port's path and end.
pub struct Pty {
    /// The simulator's end (the "master"), non-blocking.
    ours: File,
    /// The port's end, kept open so the port outlives each sender's session on it.
    _port: File,
    path: PathBuf,
}

/// Fails with the last OS error if `ret` is negative.
fn check(ret: libc::c_int) -> io::Result<libc::c_int> {
    if ret < 0 { Err(io::Error::last_os_error()) } else { Ok(ret) }
}

impl Pty {
    /// Opens a new pseudo-terminal in raw mode.
    pub fn open() -> io::Result<Pty> {
        // SAFETY: plain calls on a descriptor this function owns; `ptsname_r` writes at most
        // `name.len()` bytes, NUL included.
        let (ours, path) = unsafe {
            let fd = check(libc::posix_openpt(libc::O_RDWR | libc::O_NOCTTY))?;
            let ours = OwnedFd::from_raw_fd(fd);
            check(libc::grantpt(fd))?;
            check(libc::unlockpt(fd))?;
            let mut name = [0 as libc::c_char; PTY_PATH_MAX_BYTES];
            let err = libc::ptsname_r(fd, name.as_mut_ptr(), name.len());
            if err != 0 {
                return Err(io::Error::from_raw_os_error(err));
            }
            let path = std::ffi::CStr::from_ptr(name.as_ptr()).to_string_lossy().into_owned();
            let flags = check(libc::fcntl(fd, libc::F_GETFL))?;
            check(libc::fcntl(fd, libc::F_SETFL, flags | libc::O_NONBLOCK))?;
            (File::from(ours), PathBuf::from(path))
        };
        let port = std::fs::OpenOptions::new().read(true).write(true).custom_flags(libc::O_NOCTTY).open(&path)?;
        // SAFETY: `termios` is plain data, filled by `tcgetattr` before it is read.
        unsafe {
            let mut mode: libc::termios = core::mem::zeroed();
            check(libc::tcgetattr(port.as_raw_fd(), &mut mode))?;
            libc::cfmakeraw(&mut mode);
            check(libc::tcsetattr(port.as_raw_fd(), libc::TCSANOW, &mode))?;
        }
        Ok(Pty { ours, _port: port, path })
    }

    /// The port's path, for a sender to open.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// A reader of what senders write to the port; each read waits for bytes.
    pub fn reader(&self) -> io::Result<PtyReader> {
        Ok(PtyReader(self.ours.try_clone()?))
    }

    /// Writes the firmware's bytes to the port; those the port has no room for are dropped.
    pub fn send(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            match self.ours.write(bytes) {
                Ok(0) => return,
                Ok(n) => bytes = &bytes[n..],
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                // Full (no one reads), or gone: what a UART sends then is lost.
                Err(_) => return,
            }
        }
    }
}

/// The simulator's end of a [`Pty`], read from a thread of its own.
pub struct PtyReader(File);

impl Read for PtyReader {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        loop {
            let mut ready = libc::pollfd { fd: self.0.as_raw_fd(), events: libc::POLLIN, revents: 0 };
            // SAFETY: one valid `pollfd`, for as long as the call.
            match check(unsafe { libc::poll(&mut ready, 1, -1) }) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
                Ok(_) => {}
            }
            match self.0.read(buf) {
                Err(e) if matches!(e.kind(), io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted) => continue,
                other => return other,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    #[test]
    fn bytes_pass_both_ways_unchanged() {
        let mut pty = Pty::open().unwrap();
        let mut port = std::fs::OpenOptions::new().read(true).write(true).open(pty.path()).unwrap();
        // A line end and a realtime byte arrive as sent: no CR added, no echo, no line editing.
        port.write_all(b"G1 X1\n?\x18").unwrap();
        let mut reader = pty.reader().unwrap();
        let mut got = Vec::new();
        while got.len() < 8 {
            let mut buf = [0u8; 16];
            let n = reader.read(&mut buf).unwrap();
            got.extend_from_slice(&buf[..n]);
        }
        assert_eq!(got, b"G1 X1\n?\x18");
        pty.send(b"ok\r\n");
        let mut back = [0u8; 4];
        port.read_exact(&mut back).unwrap();
        assert_eq!(&back, b"ok\r\n");
    }

    #[test]
    fn with_no_one_reading_the_port_sending_drops_bytes_and_never_waits() {
        let mut pty = Pty::open().unwrap();
        // Far more than any port buffers: it returns, having dropped what found no room.
        for _ in 0..1000 {
            pty.send(&[b'x'; 1024]);
        }
    }
}
