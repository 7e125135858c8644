//! The foot pod's GATT server and its Bluetooth task, on trouble-host: Running Speed and
//! Cadence (0x1814), Battery (0x180F) and Device Information (0x180A), advertised as an
//! on-shoe running/walking sensor (appearance 0x0442) with 0x1814 in the advertising data.
//!
//! Generic over trouble's `Controller`: the nRF52840 firmware passes Nordic's SoftDevice
//! Controller; the host tests build the same attribute table without one and read it back.
//!
//! **Nothing is lost without a central.** The pipeline side calls [`PodLink::stride`] for
//! every stride whether or not anything is connected: the total distance lives in the
//! [`FootPod`] behind the link, the measurements queue in a small channel that the Bluetooth
//! task empties when a central connects (stale notifications are not replayed), and the
//! serial/defmt log does not depend on any of it.
//!
//! **One path for board and host.** [`run`] is what the nRF52840 build runs over Nordic's
//! controller and what `gaitclip pod` runs on the host over an HCI transport (a Bumble
//! virtual controller, or a real one over a UART); they differ in the controller, the
//! executor, the clock (`embassy-time`'s driver), the battery source
//! ([`PodLink::set_battery_percent`]) and what hears the Bluetooth events ([`PodObserver`]:
//! defmt on the board, lines on stdout on the host).

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, AtomicU32, AtomicU8, Ordering};

use embassy_futures::select::{select, Either};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use embassy_time::{Duration, Instant, Timer};
use gaitclip::record::stride::Stride;
use trouble_host::prelude::*;

use crate::rsc::{self, FootPod, Measurement, MAX_MEASUREMENT_LEN};

/// defmt on a Cortex-M; nothing on the host, where the tests build the table without a
/// logger.
macro_rules! ble_log {
    ($level:ident, $($arg:tt)*) => {{
        #[cfg(target_os = "none")]
        defmt::$level!($($arg)*);
    }};
}

/// Measurements queued for the Bluetooth task (a few strides' worth while it is busy).
pub const QUEUED_MEASUREMENTS: usize = 4;
/// Connections served at once: one watch or phone.
pub const CONNECTIONS_MAX: usize = 1;
/// L2CAP channels: signalling and ATT.
pub const L2CAP_CHANNELS_MAX: usize = 2;
/// Advertising interval while waiting for a central, ms (152.5 ms: the interval Apple's
/// accessory guidelines recommend for a fast discovery).
pub const ADVERTISING_INTERVAL_MS: u64 = 152;
/// Advertising interval while the clip sleeps, ms: a watch scanning still finds it within a
/// few seconds, and the radio's share of the still current stays near 5 µA, which keeps the
/// whole under 30 µA (`gaitclip energy`; at the guidelines' 1022.5 ms it would be 10 µA and
/// the total over). The first step brings the fast interval back.
pub const SLEEPING_ADVERTISING_INTERVAL_MS: u64 = 2000;
/// The name in the advertising data and the GAP service.
pub const DEVICE_NAME: &str = "gaitclip";

/// What happened on the Bluetooth side, for a log ([`PodObserver`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PodEvent<'a> {
    /// Advertising started, at this interval.
    Advertising {
        /// Advertising interval, ms.
        interval_ms: u64,
    },
    /// Advertising could not start or a connection failed; retried in a second.
    AdvertisingFailed,
    /// A central connected.
    Connected,
    /// The central wrote the RSC Measurement's CCCD: notifications on or off.
    Subscribed {
        /// Notifications on.
        notify: bool,
    },
    /// The central wrote the SC Control Point's CCCD: indications on or off.
    ControlPointSubscribed {
        /// Indications on.
        indicate: bool,
    },
    /// An RSC Measurement was notified (its bytes).
    Notified {
        /// The characteristic value sent.
        value: &'a [u8],
    },
    /// A write to the SC Control Point and what the pod answered: the indication it sends,
    /// or the ATT error it rejected the write with.
    ControlPoint {
        /// The value written.
        request: &'a [u8],
        /// `Ok(indication)` or `Err(ATT error code)`.
        answer: Result<&'a [u8], u8>,
    },
    /// The control point's indication was confirmed by the central (or the link closed).
    IndicationDone,
    /// The link closed (by either side, or lost), with the HCI reason code.
    Disconnected {
        /// HCI reason (0x13 remote user terminated, 0x08 connection timeout, …).
        reason: u8,
    },
}

/// Hears the Bluetooth events of [`run`]: a board logs them over defmt, the host pod prints
/// them. Called from the Bluetooth task; must not block.
pub trait PodObserver {
    /// One event.
    fn event(&self, event: PodEvent<'_>);
}

/// Logs the events over defmt (on a Cortex-M; nothing elsewhere).
pub struct DefmtObserver;

impl PodObserver for DefmtObserver {
    fn event(&self, event: PodEvent<'_>) {
        #[cfg(not(target_os = "none"))]
        let _ = event;
        #[cfg(target_os = "none")]
        match event {
            PodEvent::Advertising { interval_ms } => {
                ble_log!(info, "BLE: advertising every {=u64} ms", interval_ms)
            }
            PodEvent::AdvertisingFailed => ble_log!(warn, "BLE: advertising failed; retrying"),
            PodEvent::Connected => ble_log!(info, "BLE: central connected"),
            PodEvent::Subscribed { notify } => {
                ble_log!(info, "BLE: RSC notifications {=bool}", notify)
            }
            PodEvent::ControlPointSubscribed { indicate } => {
                ble_log!(info, "BLE: control point indications {=bool}", indicate)
            }
            PodEvent::Notified { value } => ble_log!(debug, "BLE: notified {=[u8]:x}", value),
            PodEvent::ControlPoint { request, answer } => match answer {
                Ok(ind) => ble_log!(
                    info,
                    "BLE: control point {=[u8]:x} -> {=[u8]:x}",
                    request,
                    ind
                ),
                Err(code) => ble_log!(
                    info,
                    "BLE: control point {=[u8]:x} refused {=u8:x}",
                    request,
                    code
                ),
            },
            PodEvent::IndicationDone => ble_log!(debug, "BLE: indication confirmed"),
            PodEvent::Disconnected { reason } => {
                ble_log!(info, "BLE: disconnected ({=u8:x})", reason)
            }
        }
    }
}

/// The attribute table, as trouble's `#[gatt_server]` and `#[gatt_service]` build it (the
/// macros do not carry doc comments over to what they generate, hence the `allow`).
#[allow(missing_docs)]
pub mod table {
    use super::*;

    /// The GATT server of the foot pod.
    #[gatt_server]
    pub struct FootPodServer {
        /// Running Speed and Cadence.
        pub rsc: RscService,
        /// Battery level.
        pub battery: BatteryService,
        /// Who made it and what runs on it.
        pub device_info: DeviceInformationService,
    }

    /// Running Speed and Cadence (RSCS 1.0).
    #[gatt_service(uuid = service::RUNNING_SPEED_AND_CADENCE)]
    pub struct RscService {
        /// RSC Measurement, notified per stride and about 1 Hz while standing.
        #[characteristic(uuid = characteristic::RSC_MEASUREMENT, notify)]
        pub measurement: heapless::Vec<u8, MAX_MEASUREMENT_LEN>,
        /// RSC Feature: stride length, total distance, walking or running.
        #[characteristic(uuid = characteristic::RSC_FEATURE, read, value = rsc::feature())]
        pub feature: [u8; 2],
        /// Sensor Location: top of shoe.
        #[characteristic(uuid = characteristic::SENSOR_LOCATION, read, value = rsc::SENSOR_LOCATION_TOP_OF_SHOE)]
        pub location: u8,
        /// SC Control Point: Set Cumulative Value.
        #[characteristic(uuid = characteristic::SC_CONTROL_POINT, write, indicate)]
        pub control_point: heapless::Vec<u8, { rsc::CONTROL_POINT_MAX_LEN }>,
    }

    /// Battery Service.
    #[gatt_service(uuid = service::BATTERY)]
    pub struct BatteryService {
        /// Battery level, % of the supply window the clip runs in ([`battery_percent`]).
        #[characteristic(uuid = characteristic::BATTERY_LEVEL, read, notify, value = 100)]
        pub level: u8,
    }

    /// Device Information Service.
    #[gatt_service(uuid = service::DEVICE_INFORMATION)]
    pub struct DeviceInformationService {
        /// Manufacturer Name String.
        #[characteristic(uuid = characteristic::MANUFACTURER_NAME_STRING, read, value = "gaitclip")]
        pub manufacturer: &'static str,
        /// Model Number String.
        #[characteristic(uuid = characteristic::MODEL_NUMBER_STRING, read, value = "gaitclip nRF52840 + MPU6050")]
        pub model: &'static str,
        /// Firmware Revision String: the crate's version.
        #[characteristic(uuid = characteristic::FIRMWARE_REVISION_STRING, read, value = env!("CARGO_PKG_VERSION"))]
        pub firmware: &'static str,
    }
}
pub use table::{BatteryService, DeviceInformationService, FootPodServer, RscService};

/// The lowest supply the clip runs on, mV: the MPU6050's minimum VDD (2.375 V, datasheet
/// PS-MPU-6000A-00 rev 3.4, §6.3).
pub const SUPPLY_EMPTY_MV: u32 = 2375;
/// A fresh lithium coin cell, mV (CR2032 nominal 3.0 V).
pub const SUPPLY_FULL_MV: u32 = 3000;

/// Battery level, %, of a supply voltage in mV: linear over the window the clip runs in
/// ([`SUPPLY_EMPTY_MV`]..[`SUPPLY_FULL_MV`]), clamped. It says how far the supply is from
/// where the sensor stops, not the cell's charge (a coin cell's voltage stays flat for most
/// of it and then falls).
pub const fn battery_percent(supply_mv: u32) -> u8 {
    if supply_mv <= SUPPLY_EMPTY_MV {
        0
    } else if supply_mv >= SUPPLY_FULL_MV {
        100
    } else {
        ((supply_mv - SUPPLY_EMPTY_MV) * 100 / (SUPPLY_FULL_MV - SUPPLY_EMPTY_MV)) as u8
    }
}

/// The advertising data: flags (LE general discoverable, no BR/EDR), 0x1814 among the
/// 16-bit services, the appearance and the name. `buf[..n]` for the `n` returned.
pub fn advertising_data(buf: &mut [u8; 31]) -> Result<usize, Error> {
    Ok(AdStructure::encode_slice(
        &[
            AdStructure::Flags(LE_GENERAL_DISCOVERABLE | BR_EDR_NOT_SUPPORTED),
            AdStructure::CompleteServiceUuids16(&[
                rsc::SERVICE_UUID.to_le_bytes(),
                service::BATTERY.to_le_bytes(),
            ]),
            AdStructure::Unknown {
                ty: 0x19, // Appearance
                data: &rsc::APPEARANCE_ON_SHOE.to_le_bytes(),
            },
            AdStructure::CompleteLocalName(DEVICE_NAME.as_bytes()),
        ],
        &mut buf[..],
    )?)
}

/// What the pipeline side and the Bluetooth task share: the foot pod, the queued
/// measurements, the battery level and the counters. A firmware keeps one in a static.
pub struct PodLink {
    pod: Mutex<CriticalSectionRawMutex, RefCell<FootPod>>,
    measurements: Channel<CriticalSectionRawMutex, Measurement, QUEUED_MEASUREMENTS>,
    battery_percent: AtomicU8,
    /// Measurements not queued because the queue was full (no central, or a slow one).
    unqueued: AtomicU32,
    /// Notifications sent.
    notified: AtomicU32,
    /// Connections so far.
    connections: AtomicU32,
    /// The connected central has RSC Measurement notifications on.
    subscribed: AtomicBool,
    /// The clip sleeps ([`crate::sleep`]): advertise slowly.
    asleep: AtomicBool,
    /// Raised when `asleep` changes, to restart advertising at the other interval.
    asleep_changed: Signal<CriticalSectionRawMutex, ()>,
}

impl Default for PodLink {
    fn default() -> Self {
        Self::new()
    }
}

impl PodLink {
    /// A link with a pod that has walked nowhere.
    pub const fn new() -> Self {
        PodLink {
            pod: Mutex::new(RefCell::new(FootPod::new())),
            measurements: Channel::new(),
            battery_percent: AtomicU8::new(100),
            unqueued: AtomicU32::new(0),
            notified: AtomicU32::new(0),
            connections: AtomicU32::new(0),
            subscribed: AtomicBool::new(false),
            asleep: AtomicBool::new(false),
            asleep_changed: Signal::new(),
        }
    }

    /// The clip went to sleep or woke: advertising restarts at
    /// [`SLEEPING_ADVERTISING_INTERVAL_MS`] or [`ADVERTISING_INTERVAL_MS`] (a connection
    /// already made is kept either way).
    pub fn set_asleep(&self, asleep: bool) {
        if self.asleep.swap(asleep, Ordering::Relaxed) != asleep {
            self.asleep_changed.signal(());
        }
    }

    fn advertising_interval_ms(&self) -> u64 {
        if self.asleep.load(Ordering::Relaxed) {
            SLEEPING_ADVERTISING_INTERVAL_MS
        } else {
            ADVERTISING_INTERVAL_MS
        }
    }

    /// A measured stride (every one, connected or not) at `now_ms`.
    pub fn stride(&self, stride: &Stride, now_ms: u32) {
        let m = self.pod.lock(|p| p.borrow_mut().stride(stride, now_ms));
        if self.measurements.try_send(m).is_err() {
            self.unqueued.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// The total distance, dm.
    pub fn total_distance_dm(&self) -> u32 {
        self.pod.lock(|p| p.borrow().total_distance_dm())
    }

    /// Sets the battery level notified and read, %.
    pub fn set_battery_percent(&self, percent: u8) {
        self.battery_percent
            .store(percent.min(100), Ordering::Relaxed);
    }

    /// Whether a connected central has RSC Measurement notifications on (a host replay can
    /// wait for it, so that every stride is seen).
    pub fn subscribed(&self) -> bool {
        self.subscribed.load(Ordering::Relaxed)
    }

    /// (notifications sent, measurements not queued, connections).
    pub fn counters(&self) -> (u32, u32, u32) {
        (
            self.notified.load(Ordering::Relaxed),
            self.unqueued.load(Ordering::Relaxed),
            self.connections.load(Ordering::Relaxed),
        )
    }

    fn now_ms() -> u32 {
        Instant::now().as_millis() as u32
    }
}

/// Runs the Bluetooth side forever: the host stack on `controller`, advertising, one
/// connection at a time, and advertising again after a disconnection or a link loss; every
/// event to `observer`.
pub async fn run<C: Controller>(
    controller: C,
    address: Address,
    link: &PodLink,
    observer: &impl PodObserver,
) -> ! {
    let mut resources: HostResources<DefaultPacketPool, CONNECTIONS_MAX, L2CAP_CHANNELS_MAX> =
        HostResources::new();
    let stack = trouble_host::new(controller, &mut resources)
        .set_random_address(address)
        .build();
    let mut runner = stack.runner();
    let mut peripheral = stack.peripheral();
    let server = match FootPodServer::new_with_config(GapConfig::Peripheral(PeripheralConfig {
        name: DEVICE_NAME,
        appearance: &appearance::running_walking_sensor::ON_SHOE_RUNNING_WALKING_SENSOR,
    })) {
        Ok(s) => s,
        Err(e) => fail("GATT table", e),
    };
    let host = async {
        loop {
            if let Err(e) = runner.run().await {
                ble_log!(
                    error,
                    "BLE host stopped: {}; restarting it",
                    defmt::Debug2Format(&e)
                );
                let _ = e;
            }
        }
    };
    let app = async {
        loop {
            link.asleep_changed.reset();
            let interval = link.advertising_interval_ms();
            observer.event(PodEvent::Advertising {
                interval_ms: interval,
            });
            let advertised = select(
                advertise(&mut peripheral, &server, interval),
                link.asleep_changed.wait(),
            )
            .await;
            let Either::First(advertised) = advertised else {
                // Asleep or awake now: advertise again at the other interval.
                continue;
            };
            match advertised {
                Ok(conn) => {
                    link.connections.fetch_add(1, Ordering::Relaxed);
                    observer.event(PodEvent::Connected);
                    // What queued while nobody listened is history: the total carries it.
                    link.measurements.clear();
                    serve(&server, &conn, link, observer).await;
                    link.subscribed.store(false, Ordering::Relaxed);
                }
                Err(e) => {
                    ble_log!(
                        warn,
                        "BLE: advertising failed ({}); retrying in 1 s",
                        defmt::Debug2Format(&e)
                    );
                    let _ = e;
                    observer.event(PodEvent::AdvertisingFailed);
                    Timer::after(Duration::from_secs(1)).await;
                }
            }
        }
    };
    embassy_futures::join::join(host, app).await;
    // Both loops run forever.
    loop {
        Timer::after(Duration::from_secs(3600)).await;
    }
}

/// A setup error there is no way around (the table is a compile-time shape, so only a
/// changed definition gets here): logged, then the panic handler.
fn fail(what: &str, e: impl core::fmt::Debug) -> ! {
    ble_log!(
        error,
        "BLE: {=str} failed: {}",
        what,
        defmt::Debug2Format(&e)
    );
    panic!("BLE: {what} failed: {e:?}")
}

async fn advertise<'values, 'server, C: Controller>(
    peripheral: &mut Peripheral<'values, C, DefaultPacketPool>,
    server: &'server FootPodServer<'values>,
    interval_ms: u64,
) -> Result<GattConnection<'values, 'server, DefaultPacketPool>, BleHostError<C::Error>> {
    let mut adv = [0u8; 31];
    let len = advertising_data(&mut adv)?;
    let params = AdvertisementParameters {
        interval_min: Duration::from_millis(interval_ms),
        interval_max: Duration::from_millis(interval_ms),
        ..Default::default()
    };
    let advertiser = peripheral
        .advertise(
            &params,
            Advertisement::ConnectableScannableUndirected {
                adv_data: &adv[..len],
                scan_data: &[],
            },
        )
        .await?;
    Ok(advertiser.accept().await?.with_attribute_server(server)?)
}

/// One connection: GATT events, the queued measurements and the standing notifications,
/// until it closes. A control-point answer is indicated by a second loop beside the first,
/// so that a write arriving before the central confirmed the indication is seen, and refused
/// (0x80, procedure already in progress), while the indication waits for its confirmation.
async fn serve<P: PacketPool>(
    server: &FootPodServer<'_>,
    conn: &GattConnection<'_, '_, P>,
    link: &PodLink,
    observer: &impl PodObserver,
) {
    let rsc = &server.rsc;
    let indications_to_send: Signal<CriticalSectionRawMutex, heapless::Vec<u8, 5>> = Signal::new();
    let events = serve_events(server, conn, link, observer, &indications_to_send);
    let indicate = async {
        loop {
            let v = indications_to_send.wait().await;
            if let Err(e) = rsc.control_point.indicate(conn, &v, false).await {
                ble_log!(
                    warn,
                    "BLE: control-point indication failed: {}",
                    defmt::Debug2Format(&e)
                );
                let _ = e;
            }
            link.pod.lock(|p| p.borrow_mut().indication_done());
            observer.event(PodEvent::IndicationDone);
        }
    };
    // The event loop ends with the connection; the indication loop never does.
    select(events, indicate).await;
}

/// The event loop of [`serve`].
async fn serve_events<P: PacketPool>(
    server: &FootPodServer<'_>,
    conn: &GattConnection<'_, '_, P>,
    link: &PodLink,
    observer: &impl PodObserver,
    indications_to_send: &Signal<CriticalSectionRawMutex, heapless::Vec<u8, 5>>,
) {
    let rsc = &server.rsc;
    let cp_cccd = rsc.control_point.cccd_handle().map(|h| h.handle());
    let measurement_cccd = rsc.measurement.cccd_handle().map(|h| h.handle());
    // trouble-host 0.8's `Characteristic::should_indicate` reads the notify bit, so the
    // control point's CCCD is followed here from the client's writes.
    let mut indications = false;
    // The level a central reads is the link's from the start, not the table's initial value;
    // it is notified when it changes.
    let mut battery_sent = Some(link.battery_percent.load(Ordering::Relaxed));
    if let Some(level) = battery_sent {
        let _ = server.set(&server.battery.level, &level);
    }
    loop {
        let next = select(
            conn.next(),
            select(
                link.measurements.receive(),
                Timer::after(Duration::from_millis(rsc::STANDING_EVERY_MS as u64)),
            ),
        )
        .await;
        if let Either::First(GattConnectionEvent::Gatt {
            event: GattEvent::Write(w),
        }) = &next
        {
            if w.handle() == rsc.control_point.handle
                && link.pod.lock(|p| p.borrow().procedure_pending())
            {
                // The host handles the central's PDUs in order: a confirmation it sent before
                // this write has woken the indication loop already. Let that loop finish the
                // procedure before the write is judged, so that only a write that really
                // came before the confirmation is refused as a procedure in progress.
                for _ in 0..4 {
                    embassy_futures::yield_now().await;
                }
            }
        }
        match next {
            Either::First(GattConnectionEvent::Disconnected { reason }) => {
                observer.event(PodEvent::Disconnected {
                    reason: reason.into_inner(),
                });
                link.pod.lock(|p| p.borrow_mut().indication_done());
                return;
            }
            Either::First(GattConnectionEvent::Gatt { event }) => {
                let mut response = None;
                let mut refused = None;
                let reply = match &event {
                    GattEvent::Write(w) if Some(w.handle()) == cp_cccd => {
                        indications = w.with_data(|_, d| d.first().is_some_and(|b| b & 0x02 != 0));
                        observer.event(PodEvent::ControlPointSubscribed {
                            indicate: indications,
                        });
                        event.accept()
                    }
                    GattEvent::Write(w) if Some(w.handle()) == measurement_cccd => {
                        let on = w.with_data(|_, d| d.first().is_some_and(|b| b & 0x01 != 0));
                        link.subscribed.store(on, Ordering::Relaxed);
                        observer.event(PodEvent::Subscribed { notify: on });
                        event.accept()
                    }
                    GattEvent::Write(w) if w.handle() == rsc.control_point.handle => {
                        let mut request = heapless::Vec::<u8, 8>::new();
                        let answer = w.with_data(|_, d| {
                            let _ = request.extend_from_slice(&d[..d.len().min(8)]);
                            link.pod
                                .lock(|p| p.borrow_mut().control_point(d, indications))
                        });
                        match answer {
                            Ok(r) => {
                                response = Some(r);
                                observer.event(PodEvent::ControlPoint {
                                    request: &request,
                                    answer: Ok(&r),
                                });
                                event.accept()
                            }
                            Err(refusal) => {
                                refused = Some(refusal.att_error());
                                observer.event(PodEvent::ControlPoint {
                                    request: &request,
                                    answer: Err(refusal.att_error()),
                                });
                                event.reject(AttErrorCode::new(refusal.att_error()))
                            }
                        }
                    }
                    _ => event.accept(),
                };
                let _ = refused;
                if let Ok(reply) = reply {
                    reply.send().await;
                }
                if let Some(r) = response {
                    let mut v = heapless::Vec::new();
                    let _ = v.extend_from_slice(&r);
                    indications_to_send.signal(v);
                }
            }
            Either::First(_) => {}
            Either::Second(Either::First(m)) => notify(rsc, conn, link, observer, &m).await,
            Either::Second(Either::Second(())) => {
                let standing = link
                    .pod
                    .lock(|p| p.borrow_mut().standing_due(PodLink::now_ms()));
                if let Some(m) = standing {
                    notify(rsc, conn, link, observer, &m).await;
                }
                let level = link.battery_percent.load(Ordering::Relaxed);
                if battery_sent != Some(level) {
                    let _ = server.set(&server.battery.level, &level);
                    if server
                        .battery
                        .level
                        .notify(conn, &level, true)
                        .await
                        .is_ok()
                    {
                        battery_sent = Some(level);
                    }
                }
            }
        }
    }
}

/// Notifies `m` if the central subscribed (a measurement before the subscription is not
/// sent: the total distance carries it).
async fn notify<P: PacketPool>(
    rsc: &RscService,
    conn: &GattConnection<'_, '_, P>,
    link: &PodLink,
    observer: &impl PodObserver,
    m: &Measurement,
) {
    if !rsc.measurement.should_notify(conn) {
        return;
    }
    let mut buf = [0u8; MAX_MEASUREMENT_LEN];
    let n = m.encode(&mut buf);
    let mut v = heapless::Vec::new();
    let _ = v.extend_from_slice(&buf[..n]);
    if rsc.measurement.notify(conn, &v, false).await.is_ok() {
        link.notified.fetch_add(1, Ordering::Relaxed);
        observer.event(PodEvent::Notified { value: &buf[..n] });
    }
}
