//! `gaitclip pod`: the Bluetooth foot pod on the host, over HCI.
//!
//! The pod's own Bluetooth code — [`gaitclip_board::rsc_gatt::run`], its [`PodLink`] and the
//! [`gaitclip_board::rsc::FootPod`] behind it, exactly as `boards/nrf52840-ble` runs them —
//! on trouble-host over an external HCI controller: the TCP client of an H4 controller
//! (Bumble's `tcp-server:`), or a UART controller (Zephyr's `hci_uart` on an nRF52840
//! dongle). A recording is replayed through the same core as `gaitclip replay`, in real time
//! or `--speed` times faster, and every stride goes to the link as the board's pipeline task
//! hands it over.
//!
//! What differs from the board, and only that: the controller (an `ExternalController` over
//! a byte stream instead of Nordic's SoftDevice Controller), the executor (tokio's current
//! thread instead of embassy's), the clock (`embassy-time`'s std driver), the battery
//! (`--battery-percent` instead of the SAADC) and the log ([`PodObserver`] printing lines
//! on stdout instead of defmt).
//!
//! Output, one line each: the replay's strides (as `gaitclip replay` prints them, or as its
//! JSON with `--json`), every Bluetooth event (`ble …`, or `{"ble": …}`), and the summary
//! when the recording ends. The pod then keeps serving (standing notifications, the control
//! point) until SIGINT, when it prints its counters and exits with status 0.

use std::io::Write as _;
use std::str::FromStr;
use std::time::Duration;

use anyhow::{bail, Context, Result};
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embedded_io_adapters::tokio_1::FromTokio;
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::Pipeline;
use gaitclip_board::rsc_gatt::{self, PodEvent, PodLink, PodObserver};
use serde_json::json;
use trouble_host::prelude::{Address, ExternalController};

use crate::io::trace::{Ranges, Trace};
use crate::replay::{self, Prepared};

/// Where the HCI controller is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Hci {
    /// An H4 controller listening on TCP (`tcp:HOST:PORT`).
    Tcp(String),
    /// An H4 controller on a UART (`serial:PATH[@BAUD]`, 1 000 000 baud by default, no
    /// flow control: Zephyr's `hci_uart` on an nRF52840 dongle).
    Serial {
        /// The device.
        path: String,
        /// Baud rate.
        baud: u32,
    },
}

impl FromStr for Hci {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        if let Some(addr) = s.strip_prefix("tcp:") {
            if addr
                .rsplit_once(':')
                .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok())
            {
                return Ok(Hci::Tcp(addr.to_string()));
            }
            return Err(format!("`{s}`: expected tcp:HOST:PORT"));
        }
        if let Some(rest) = s.strip_prefix("serial:") {
            let (path, baud) = match rest.rsplit_once('@') {
                Some((p, b)) => (
                    p,
                    b.parse::<u32>()
                        .map_err(|_| format!("`{s}`: the baud rate `{b}` is not a number"))?,
                ),
                None => (rest, 1_000_000),
            };
            if path.is_empty() {
                return Err(format!("`{s}`: expected serial:PATH[@BAUD]"));
            }
            return Ok(Hci::Serial {
                path: path.to_string(),
                baud,
            });
        }
        Err(format!(
            "`{s}`: expected tcp:HOST:PORT or serial:PATH[@BAUD]"
        ))
    }
}

/// What `gaitclip pod` runs.
pub struct PodOptions {
    /// The controller.
    pub hci: Hci,
    /// The recording.
    pub trace: Trace,
    /// Replay this many times faster than real time.
    pub speed: f64,
    /// Hold the replay until a central has subscribed to RSC Measurement.
    pub wait_for_central: bool,
    /// The battery level served, %.
    pub battery_percent: u8,
    /// The core's configuration beyond the recording's (detector, model).
    pub configure: Box<dyn Fn(&mut Config)>,
    /// Strides and events as JSON lines.
    pub json: bool,
}

/// The pod's static random address (the two top bits set, as a static address has them).
pub const ADDRESS: [u8; 6] = [0xda, 0x4c, 0x3d, 0x2e, 0x1f, 0xc0];

/// HCI command slots of the external controller.
const CONTROLLER_SLOTS: usize = 10;

/// Prints the Bluetooth events, one line each.
struct Printer {
    json: bool,
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

impl PodObserver for Printer {
    fn event(&self, e: PodEvent<'_>) {
        let (kind, fields) = match e {
            PodEvent::Advertising { interval_ms } => {
                ("advertising", json!({ "interval_ms": interval_ms }))
            }
            PodEvent::AdvertisingFailed => ("advertising_failed", json!({})),
            PodEvent::Connected => ("connected", json!({})),
            PodEvent::Subscribed { notify } => ("subscribed", json!({ "notify": notify })),
            PodEvent::ControlPointSubscribed { indicate } => {
                ("control_point_subscribed", json!({ "indicate": indicate }))
            }
            PodEvent::Notified { value } => ("notified", json!({ "value": hex(value) })),
            PodEvent::ControlPoint { request, answer } => (
                "control_point",
                match answer {
                    Ok(ind) => json!({ "request": hex(request), "indication": hex(ind) }),
                    Err(code) => json!({ "request": hex(request), "att_error": code }),
                },
            ),
            PodEvent::IndicationDone => ("indication_done", json!({})),
            PodEvent::Disconnected { reason } => ("disconnected", json!({ "reason": reason })),
        };
        let line = if self.json {
            let mut o = json!({ "event": kind });
            if let (Some(o), Some(f)) = (o.as_object_mut(), fields.as_object()) {
                o.extend(f.clone());
            }
            json!({ "ble": o }).to_string()
        } else {
            let f: Vec<String> = fields
                .as_object()
                .map(|m| m.iter().map(|(k, v)| format!("{k}={v}")).collect())
                .unwrap_or_default();
            format!("ble {kind} {}", f.join(" ")).trim_end().to_string()
        };
        let mut out = std::io::stdout().lock();
        let _ = writeln!(out, "{line}");
        let _ = out.flush();
    }
}

/// The link every stride goes to, as the board's static.
static LINK: PodLink = PodLink::new();

/// Runs the pod until SIGINT (or a fatal transport error).
pub fn run(opts: PodOptions) -> Result<()> {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("tokio runtime")?;
    // The pod runs as a task of its own, not as `block_on`'s future: embassy-sync and
    // trouble-host re-register their wakers on every poll and wake the old one when
    // `Waker::will_wake` says it differs, and the clones of tokio's `block_on` waker compare
    // unequal to it (its vtable is instantiated in more than one codegen unit), so each poll
    // woke the pod again: more than a core spent polling (perf, gdb: `WakerRegistration::
    // register` in embassy-sync's channel and trouble-host's connection manager). A task's
    // waker has one vtable.
    let local = tokio::task::LocalSet::new();
    local.block_on(&rt, async move {
        tokio::task::spawn_local(run_async(opts))
            .await
            .context("the pod's task")?
    })
}

async fn run_async(opts: PodOptions) -> Result<()> {
    let ranges = Ranges::default();
    let prepared = replay::prepare(&opts.trace, ranges)?;
    let mut config = prepared.config(ranges);
    (opts.configure)(&mut config);
    if !(opts.speed.is_finite() && opts.speed > 0.0) {
        bail!("--speed must be a positive number");
    }
    LINK.set_battery_percent(opts.battery_percent);
    let printer = Printer { json: opts.json };
    let address = Address::random(ADDRESS);
    match &opts.hci {
        Hci::Tcp(addr) => {
            let stream = tokio::net::TcpStream::connect(addr)
                .await
                .with_context(|| format!("no HCI controller at tcp:{addr}"))?;
            stream.set_nodelay(true)?;
            let (r, w) = stream.into_split();
            serve_h4(r, w, address, &printer, &prepared, config, &opts).await
        }
        Hci::Serial { path, baud } => {
            use tokio_serial::SerialPortBuilderExt;
            let port = tokio_serial::new(path, *baud)
                .flow_control(tokio_serial::FlowControl::None)
                .open_native_async()
                .with_context(|| format!("cannot open serial:{path}@{baud}"))?;
            let (r, w) = tokio::io::split(port);
            serve_h4(r, w, address, &printer, &prepared, config, &opts).await
        }
    }
}

/// The foot pod over one H4 byte stream, whatever carries its two halves (TCP or a UART).
async fn serve_h4<R, W>(
    r: R,
    w: W,
    address: Address,
    printer: &Printer,
    prepared: &Prepared,
    config: Config,
    opts: &PodOptions,
) -> Result<()>
where
    R: tokio::io::AsyncRead + Unpin,
    W: tokio::io::AsyncWrite + Unpin,
{
    let transport = bt_hci_serial::SerialTransport::<NoopRawMutex, _, _>::new(
        FromTokio::new(r),
        FromTokio::new(w),
    );
    let controller = ExternalController::<_, CONTROLLER_SLOTS>::new(transport);
    serve(
        rsc_gatt::run(controller, address, &LINK, printer),
        prepared,
        config,
        opts,
    )
    .await
}

/// The Bluetooth side, the replay and SIGINT, together.
async fn serve(
    ble: impl std::future::Future,
    prepared: &Prepared,
    config: Config,
    opts: &PodOptions,
) -> Result<()> {
    let replay = async {
        if opts.wait_for_central {
            while !LINK.subscribed() {
                tokio::time::sleep(Duration::from_millis(10)).await;
            }
        }
        feed(prepared, config, opts).await;
        // Served on until SIGINT: standing notifications, the control point, reconnections.
        std::future::pending::<()>().await
    };
    tokio::select! {
        _ = ble => unreachable!("the Bluetooth side runs forever"),
        _ = replay => unreachable!("the replay waits for SIGINT"),
        r = tokio::signal::ctrl_c() => r.context("SIGINT")?,
    }
    let (notified, unqueued, connections) = LINK.counters();
    let line = json!({
        "notified": notified,
        "unqueued": unqueued,
        "connections": connections,
        "total_distance_dm": LINK.total_distance_dm(),
    });
    if opts.json {
        println!("{}", json!({ "pod_stopped": line }));
    } else {
        println!("pod stopped: {line}");
    }
    Ok(())
}

/// How far ahead of its time a sample may be fed: the replay wakes at most once per this.
const PACE_BURST: Duration = Duration::from_millis(10);

/// The recording through the core, sample by sample at its own pace over `opts.speed`
/// (in bursts of at most [`PACE_BURST`]), every stride printed and handed to the link.
async fn feed(prepared: &Prepared, config: Config, opts: &PodOptions) {
    let clock = &prepared.clock;
    let mut p = Pipeline::new(config);
    let start = tokio::time::Instant::now();
    let t0 = clock.t_s(0);
    let mut holes = clock.holes.iter().peekable();
    let emit = |s: gaitclip::record::stride::Stride| {
        let r = replay::report(s, config, &|n| clock.t_s(n));
        LINK.stride(&s, embassy_time::Instant::now().as_millis() as u32);
        let mut out = std::io::stdout().lock();
        let _ = if opts.json {
            writeln!(out, "{}", serde_json::to_string(&r).unwrap_or_default())
        } else {
            writeln!(
                out,
                "stride {:3}  start {:8.3} s  dur {:5.3} s  length {:5.3} m{}",
                r.index,
                r.start_s,
                r.end_s - r.start_s,
                r.length_m,
                if r.flags.is_empty() {
                    String::new()
                } else {
                    format!("  ({})", r.flags.join(","))
                }
            )
        };
        let _ = out.flush();
    };
    for (i, s) in prepared.counts.iter().enumerate() {
        while let Some(g) = holes.next_if(|g| g.before <= i) {
            if let Some(st) = p.gap(g.missing) {
                emit(st);
            }
        }
        let due =
            start + Duration::from_secs_f64((clock.t_s(p.next_index()) - t0).max(0.0) / opts.speed);
        // Samples are fed in bursts of up to PACE_BURST, as the board's sampler drains its
        // FIFO, not one timer wake-up per sample: at 200 Hz × 30 (the Bluetooth tests'
        // soak) that was 6 000 wake-ups a second and more than a core spent waking.
        if due > tokio::time::Instant::now() + PACE_BURST {
            tokio::time::sleep_until(due).await;
        }
        if let Some(st) = p.process(s) {
            emit(st);
        }
    }
    while let Some(st) = p.finish() {
        emit(st);
    }
    let (_, summary) = prepared.run(config);
    if opts.json {
        println!("{}", json!({ "summary": summary }));
    } else {
        println!("{}", summary.line());
    }
}
