//! The USB OTG FS port (PA11 DM, PA12 DP, VBUS sensed on PA9) as a CDC-ACM serial port: the USB
//! device and its descriptors, its task, and the port's two ends as embedded-io streams for the
//! host link.
//!
//! The port is open while the host holds DTR set, as serial programs do from opening a port to
//! closing it. While it is closed (or the cable is out) reads wait for the next opening and
//! answers go nowhere, as a UART's do with no cable: a closed port never holds up the host link.
//! Each opening is read once as a [`UsbSerialError::Opened`] error, so the host link can greet
//! the host, and each closing once as a [`UsbSerialError::Closed`] error, so it can drop the line
//! the host was in the middle of sending. A host that keeps the port open but stops reading
//! loses what is written to it after `USB_WRITE_TIMEOUT_MS` rather than stalling the other link.
//!
//! The port holds the host back: the driver takes one packet from the host and then answers the
//! next with NAK until the packet has been read, and a packet is read only once the last one has
//! been taken. A host link that reads only when it has room therefore never loses a byte: the
//! host's writes wait meanwhile.

use embassy_executor::Spawner;
use embassy_futures::select::{Either, select};
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::{PA11, PA12, USB_OTG_FS};
use embassy_stm32::usb::{self, Driver};
use embassy_stm32::{Peri, bind_interrupts, interrupt, uid};
use embassy_time::{Duration, with_timeout};
use embassy_usb::class::cdc_acm::{CdcAcmClass, ControlChanged, Receiver, Sender, State};
use embassy_usb::driver::EndpointError;
use embassy_usb::{Builder, UsbDevice};
use static_cell::StaticCell;

use crate::firmware::polls;
use servoplot::tasks::serial::{PORT_CLOSED, PORT_OPENED};

/// pid.codes' vendor ID for open hardware, and its test product ID (1209:0001).
const USB_VID: u16 = 0x1209;
const USB_PID: u16 = 0x0001;
const USB_MANUFACTURER: &str = "servoplot";
const USB_PRODUCT: &str = "servoplot plotter";
/// Full-speed bulk packets, the largest the data endpoints allow.
const USB_PACKET_BYTES: usize = 64;
/// Received packets wait here for the driver: control endpoint and data endpoint, one each.
const USB_EP_OUT_BUFFER_BYTES: usize = 2 * USB_PACKET_BYTES;
/// The configuration descriptor of one CDC-ACM function takes 75 bytes, the BOS descriptor 12.
const USB_CONFIG_DESCRIPTOR_BYTES: usize = 96;
const USB_BOS_DESCRIPTOR_BYTES: usize = 16;
/// Control requests' data: line coding (7 bytes) and the string descriptors (the product name
/// as UTF-16, 36 bytes).
const USB_CONTROL_BUFFER_BYTES: usize = 64;
/// How long one packet may wait for an open port's host to take it before it is dropped.
const USB_WRITE_TIMEOUT_MS: u64 = 100;

bind_interrupts!(struct Irqs {
    OTG_FS => usb::InterruptHandler<USB_OTG_FS>;
});

type UsbDriver = Driver<'static, USB_OTG_FS>;

#[embassy_executor::task]
async fn usb_device(mut device: UsbDevice<'static, UsbDriver>) -> ! {
    device.run().await
}

/// Starts the USB device on the OTG FS port, its interrupt at `priority`, its task on
/// `spawner`, and returns the serial port's two ends.
pub fn start(
    spawner: Spawner,
    otg: Peri<'static, USB_OTG_FS>,
    dp: Peri<'static, PA12>,
    dm: Peri<'static, PA11>,
    priority: Priority,
) -> (UsbRx, UsbTx) {
    static EP_OUT_BUFFER: StaticCell<[u8; USB_EP_OUT_BUFFER_BYTES]> = StaticCell::new();
    static CONFIG_DESCRIPTOR: StaticCell<[u8; USB_CONFIG_DESCRIPTOR_BYTES]> = StaticCell::new();
    static BOS_DESCRIPTOR: StaticCell<[u8; USB_BOS_DESCRIPTOR_BYTES]> = StaticCell::new();
    static CONTROL_BUFFER: StaticCell<[u8; USB_CONTROL_BUFFER_BYTES]> = StaticCell::new();
    static CDC_STATE: StaticCell<State> = StaticCell::new();

    let mut driver_config = usb::Config::default();
    // The board has its own supply: without sensing VBUS it could not tell the cable was pulled.
    driver_config.vbus_detection = true;
    let ep_out_buffer = EP_OUT_BUFFER.init([0; USB_EP_OUT_BUFFER_BYTES]);
    let driver = Driver::new_fs(otg, Irqs, dp, dm, ep_out_buffer, driver_config);

    let mut config = embassy_usb::Config::new(USB_VID, USB_PID);
    config.manufacturer = Some(USB_MANUFACTURER);
    config.product = Some(USB_PRODUCT);
    config.serial_number = Some(uid::uid_hex());
    config.self_powered = true;
    config.max_power = 0;
    let mut builder = Builder::new(
        driver,
        config,
        CONFIG_DESCRIPTOR.init([0; USB_CONFIG_DESCRIPTOR_BYTES]),
        BOS_DESCRIPTOR.init([0; USB_BOS_DESCRIPTOR_BYTES]),
        &mut [],
        CONTROL_BUFFER.init([0; USB_CONTROL_BUFFER_BYTES]),
    );
    let class = CdcAcmClass::new(&mut builder, CDC_STATE.init(State::new()), USB_PACKET_BYTES as u16);
    let (tx, rx, control) = class.split_with_control();

    interrupt::OTG_FS.set_priority(priority);
    match usb_device(builder.build()) {
        Ok(token) => {
            polls::register(token.id(), "usb", polls::Executor::ThreadMode);
            spawner.spawn(token);
        }
        Err(_) => defmt::panic!("the USB device's task spawned twice"),
    }
    (
        UsbRx { rx, control, open: false, packet: [0; USB_PACKET_BYTES], start: 0, end: 0 },
        UsbTx { tx, packet_full: false },
    )
}

/// Why a read or write on the port did not happen.
#[derive(Debug, defmt::Format)]
pub enum UsbSerialError {
    /// The host opened the port (set DTR) since the last read.
    Opened,
    /// The host closed the port (or the cable was pulled) since the last read.
    Closed,
    /// The host kept the port open but did not take a packet in time.
    TimedOut,
}

impl core::fmt::Display for UsbSerialError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            UsbSerialError::Opened => "port opened",
            UsbSerialError::Closed => "port closed",
            UsbSerialError::TimedOut => "host not reading",
        })
    }
}

impl core::error::Error for UsbSerialError {}

impl embedded_io_async::Error for UsbSerialError {
    fn kind(&self) -> embedded_io_async::ErrorKind {
        match self {
            UsbSerialError::Opened => PORT_OPENED,
            UsbSerialError::Closed => PORT_CLOSED,
            UsbSerialError::TimedOut => embedded_io_async::ErrorKind::TimedOut,
        }
    }
}

/// What the host sends on the port.
pub struct UsbRx {
    rx: Receiver<'static, UsbDriver>,
    control: ControlChanged<'static>,
    open: bool,
    /// The packet being read, `start..end` not read yet.
    packet: [u8; USB_PACKET_BYTES],
    start: usize,
    end: usize,
}

impl UsbRx {
    /// Waits until the host has configured the device and opened the port.
    async fn opened(&mut self) {
        self.rx.wait_connection().await;
        while !self.control.dtr() {
            self.control.control_changed().await;
        }
    }
}

/// Waits until the host closes the port.
async fn closed(control: &ControlChanged<'static>) {
    while control.dtr() {
        control.control_changed().await;
    }
}

impl embedded_io_async::ErrorType for UsbRx {
    type Error = UsbSerialError;
}

impl embedded_io_async::Read for UsbRx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, UsbSerialError> {
        if !self.open {
            self.opened().await;
            self.open = true;
            return Err(UsbSerialError::Opened);
        }
        if self.start == self.end {
            match select(self.rx.read_packet(&mut self.packet), closed(&self.control)).await {
                Either::First(Ok(n)) => (self.start, self.end) = (0, n),
                // Unplugged, reset by the host, or closed: what came before belongs to a session
                // that is over.
                Either::First(Err(_)) | Either::Second(()) => {
                    self.open = false;
                    (self.start, self.end) = (0, 0);
                    return Err(UsbSerialError::Closed);
                }
            }
        }
        let n = buf.len().min(self.end - self.start);
        buf[..n].copy_from_slice(&self.packet[self.start..self.start + n]);
        self.start += n;
        Ok(n)
    }
}

/// What the firmware sends the host on the port.
pub struct UsbTx {
    tx: Sender<'static, UsbDriver>,
    /// The last packet sent was a full one: the host sees the data once a shorter packet ends
    /// the transfer.
    packet_full: bool,
}

impl UsbTx {
    async fn packet(&mut self, data: &[u8]) -> Result<(), UsbSerialError> {
        match with_timeout(Duration::from_millis(USB_WRITE_TIMEOUT_MS), self.tx.write_packet(data)).await {
            Ok(Ok(())) => {
                self.packet_full = data.len() == USB_PACKET_BYTES;
                Ok(())
            }
            // Unplugged or reset meanwhile: the data goes nowhere.
            Ok(Err(EndpointError::Disabled | EndpointError::BufferOverflow)) => Ok(()),
            Err(_) => Err(UsbSerialError::TimedOut),
        }
    }
}

impl embedded_io_async::ErrorType for UsbTx {
    type Error = UsbSerialError;
}

impl embedded_io_async::Write for UsbTx {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, UsbSerialError> {
        if !self.tx.dtr() {
            // Nobody has the port open.
            self.packet_full = false;
            return Ok(buf.len());
        }
        let n = buf.len().min(USB_PACKET_BYTES);
        self.packet(&buf[..n]).await?;
        Ok(n)
    }

    async fn flush(&mut self) -> Result<(), UsbSerialError> {
        if self.packet_full && self.tx.dtr() {
            // A zero-length packet ends the transfer.
            self.packet(&[]).await?;
        }
        self.packet_full = false;
        Ok(())
    }
}
