//! gaitclip on an nRF52840 with Bluetooth: a Running Speed and Cadence foot pod.
//!
//! Same pin-out as the plain nRF52840 build (`boards/nrf52840-dk`):
//!
//! | MPU6050 | nRF52840-DK | |
//! |---|---|---|
//! | SDA | P0.26 | TWIM0, 400 kHz (4.7 kΩ pull-ups on the breakout) |
//! | SCL | P0.27 | |
//! | INT | P0.03 | GPIOTE channel 0, rising edge |
//! | VCC / GND | VDD / GND | 3.3 V (or the coin cell) |
//! | serial out | P0.06 (TXD) | UARTE0, 115 200 8N1: the DK's USB virtual COM port |
//!
//! Built with `--features lsm6dsv320x` it samples an LSM6DSV320X on the same pins instead
//! (SA0 to ground, INT1 as INT): 240 Hz, its FIFO read whenever INT1 says it holds its
//! watermark, the high-g channel merged into the accelerometer
//! ([`gaitclip_board::live_settings::lsm6dsv320x`]).
//!
//! **Priorities.** Nordic's SoftDevice Controller owns the radio, RTC0 and TIMER0 at
//! priority 0 and its low-priority work at 4 (nrf-mpsl sets them). The sampler runs in an
//! interrupt executor at priority 3, woken by GPIOTE at 2: it reads the FIFO every
//! [`MODE`]'s batch of data-ready pulses and ticks the sensor watchdog, and is never held up by
//! the Bluetooth host or the pipeline, which run in thread mode. Critical sections are
//! nrf-mpsl's: they mask the application's interrupts, never the radio's.
//!
//! **Flow.** sampler (interrupt executor) → SPSC queue of [`QUEUE_LEN`] items → pipeline task
//! (thread mode): defmt and serial lines as on every board, and each stride to the
//! [`PodLink`], which keeps the total distance and queues the RSC notification → Bluetooth
//! task ([`rsc_gatt::run`]): advertising, one central, notifications, the control point, and
//! advertising again after a link loss. The status line every minute adds the Bluetooth
//! counters and the stack's high-water mark.

#![no_std]
#![no_main]

use core::cell::Cell;
use core::fmt::Write;

use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, Spawner};
use embassy_futures::select::{select3, Either3};
use embassy_nrf::gpio::{Input, Pull};
use embassy_nrf::gpiote::{InputChannel, InputChannelPolarity};
use embassy_nrf::interrupt::{self, InterruptExt, Priority};
use embassy_nrf::mode::Async;
use embassy_nrf::peripherals::{self, RNG, TWISPI0, UARTE0};
use embassy_nrf::{bind_interrupts, pac, rng, saadc, twim, uarte, Peri};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::signal::Signal;
use embassy_time::{Delay, Duration, Instant, Ticker, Timer};
use gaitclip::pipeline::Pipeline;
use gaitclip_board::imu_sampler::asynch::ImuSampler;
use gaitclip_board::imu_sampler::{BusRecovery, Counters, Item};
use gaitclip_board::live_app::{self, Drain, Watchdog, WATCHDOG_TICK_MS};
use gaitclip_board::live_settings::MOVEMENT_SAMPLES;
use gaitclip_board::live_settings::{self, CONFIG, MODE, QUEUE_LEN, RATE, SLEEP};
use gaitclip_board::rsc_gatt::{self, battery_percent, PodLink};
use gaitclip_board::sleep::SleepPolicy;
use gaitclip_board::stride_log::StrideLog;
use gaitclip_board::{serial_line, stack_paint, Steps};
use heapless::spsc::{Consumer, Producer, Queue};
use nrf_sdc::mpsl::MultiprotocolServiceLayer;
use nrf_sdc::{self as sdc, mpsl};
use panic_probe as _;
use static_cell::{ConstStaticCell, StaticCell};
use trouble_host::prelude::{Address as BleAddress, DefaultPacketPool, PacketPool};

/// The core clock, 64 MHz.
const CYCLES_PER_US: u32 = 64;
/// Interval of the supply measurement for the Battery Service.
const BATTERY_EVERY_S: u64 = 60;
/// The SoftDevice Controller's memory for one peripheral link with trouble's buffers
/// (what `sdc::Builder::build` asks for with this configuration, rounded up).
const SDC_MEM: usize = 4720;
/// Outgoing and incoming L2CAP buffers per link.
const L2CAP_TXQ: u8 = 3;
const L2CAP_RXQ: u8 = 3;

bind_interrupts!(struct Irqs {
    RNG => rng::InterruptHandler<RNG>;
    EGU0_SWI0 => mpsl::LowPrioInterruptHandler;
    CLOCK_POWER => mpsl::ClockInterruptHandler;
    RADIO => mpsl::HighPrioInterruptHandler;
    TIMER0 => mpsl::HighPrioInterruptHandler;
    RTC0 => mpsl::HighPrioInterruptHandler;
    TWISPI0 => twim::InterruptHandler<TWISPI0>;
    UARTE0 => uarte::InterruptHandler<UARTE0>;
    SAADC => saadc::InterruptHandler;
});

/// The sampler's executor, on a software interrupt above thread mode.
static SAMPLER_EXECUTOR: InterruptExecutor = InterruptExecutor::new();
static QUEUE: ConstStaticCell<Queue<Item, QUEUE_LEN>> = ConstStaticCell::new(Queue::new());
static PIPELINE: ConstStaticCell<Pipeline<Steps<MOVEMENT_SAMPLES>>> = ConstStaticCell::new(
    Pipeline::with_detector(CONFIG, Steps::new(&CONFIG.detect())),
);
/// Raised by the sampler after every data-ready pulse it handled.
static QUEUED: Signal<CriticalSectionRawMutex, ()> = Signal::new();
/// The pipeline task's sleep request for the sampler: the sample count to sleep after.
static SLEEP_REQUEST: Signal<CriticalSectionRawMutex, u32> = Signal::new();
/// Samples dropped after a wake-up while the gyro settles.
const SETTLE: u32 = SleepPolicy::settle_samples(RATE, &SLEEP);
/// The sampler's fault counters, for the status line.
static COUNTERS: Mutex<CriticalSectionRawMutex, Cell<Counters>> =
    Mutex::new(Cell::new(Counters::ZERO));
/// The foot pod, between the pipeline task and the Bluetooth task.
static POD: PodLink = PodLink::new();

/// The sampler executor's interrupt (cortex-m-rt's attribute, checked against the PAC's
/// interrupt names).
mod sampler_interrupt {
    use cortex_m_rt::interrupt;
    use embassy_nrf::pac::Interrupt as interrupt;

    #[interrupt]
    unsafe fn EGU1_SWI1() {
        // Note(unsafe): the executor's documented entry point, called only from its own
        // interrupt.
        unsafe { super::SAMPLER_EXECUTOR.on_interrupt() }
    }
}

/// TWIM0 that clocks a stuck bus free through the GPIO registers while the TWIM is off.
struct Bus {
    twim: twim::Twim<'static>,
}

impl embedded_hal::i2c::ErrorType for Bus {
    type Error = twim::Error;
}

/// EasyDMA transfers awaited: the sampler task yields while the bytes move and the core
/// sleeps (a blocking transfer would spin for the 0.4 ms of a 14-byte burst at 400 kHz).
impl embedded_hal_async::i2c::I2c for Bus {
    async fn transaction(
        &mut self,
        address: u8,
        operations: &mut [embedded_hal::i2c::Operation<'_>],
    ) -> Result<(), Self::Error> {
        self.twim.transaction(address, operations).await
    }
}

/// SCL: P0.27.
const SCL_PIN: usize = 27;

impl BusRecovery for Bus {
    fn recover_bus(&mut self) -> bool {
        let twim = pac::TWIM0;
        twim.enable()
            .write(|w| w.set_enable(pac::twim::vals::Enable::Disabled));
        // With the TWIM off the GPIO drives the pin; it stays configured as the TWIM left it
        // (output, standard-0 disconnect-1: open drain), so writing OUT clocks it.
        let p0 = pac::P0;
        let mut scl = ScL { p0 };
        live_app::clock_bus_free(&mut scl, CYCLES_PER_US);
        p0.outset().write(|w| w.set_pin(SCL_PIN, true));
        twim.enable()
            .write(|w| w.set_enable(pac::twim::vals::Enable::Enabled));
        true
    }
}

/// P0.27 as an output pin, by register.
struct ScL {
    p0: pac::gpio::Gpio,
}

impl embedded_hal::digital::ErrorType for ScL {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::OutputPin for ScL {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.p0.outclr().write(|w| w.set_pin(SCL_PIN, true));
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.p0.outset().write(|w| w.set_pin(SCL_PIN, true));
        Ok(())
    }
}

/// UARTE0's transmitter as a `fmt::Write`: text is copied through RAM (EasyDMA reads only
/// RAM), 64 bytes at a time, blocking.
struct Serial {
    tx: uarte::UarteTx<'static>,
}

impl Write for Serial {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let mut buf = [0u8; 64];
        for chunk in s.as_bytes().chunks(buf.len()) {
            buf[..chunk.len()].copy_from_slice(chunk);
            self.tx
                .blocking_write(&buf[..chunk.len()])
                .map_err(|_| core::fmt::Error)?;
        }
        Ok(())
    }
}

fn now_ms() -> u32 {
    Instant::now().as_millis() as u32
}

#[embassy_executor::task]
async fn mpsl_task(mpsl: &'static MultiprotocolServiceLayer<'static>) -> ! {
    mpsl.run().await
}

/// The sampler: a FIFO burst every [`MODE`]'s batch of pulses of INT (GPIOTE channel 0's rising
/// edge, which catches the 50 µs pulses), and the sensor watchdog. While the sensor waits
/// for motion ([`gaitclip_board::sleep`]) the channel is released and INT is watched by the
/// pin's SENSE (the PORT event: no high-frequency clock requested; the latched motion
/// interrupt is a level it cannot miss), with no watchdog ticks; the sleep is timed on
/// embassy's RTC time base.
#[embassy_executor::task]
async fn sampler_task(
    mut sampler: ImuSampler<live_settings::AsyncSource<Bus>, Delay>,
    mut producer: Producer<'static, Item>,
    mut channel: Peri<'static, peripherals::GPIOTE_CH0>,
    mut int_pin: Peri<'static, peripherals::P0_03>,
) -> ! {
    let mut ticker = Ticker::every(Duration::from_millis(WATCHDOG_TICK_MS as u64));
    let mut watchdog = Watchdog::new();
    let mut pulses = 0u32;
    let mut push = |item| producer.enqueue(item).is_ok();
    loop {
        {
            let mut int = InputChannel::new(
                channel.reborrow(),
                int_pin.reborrow(),
                Pull::None,
                InputChannelPolarity::LoToHi,
            );
            while !sampler.asleep() {
                match select3(int.wait(), ticker.next(), SLEEP_REQUEST.wait()).await {
                    Either3::First(()) => {
                        pulses = pulses.wrapping_add(1);
                        sampler.on_data_ready(&mut push).await;
                    }
                    Either3::Second(()) => {
                        if let Some(lost) =
                            watchdog.tick(pulses, RATE.samples_in_ms(WATCHDOG_TICK_MS))
                        {
                            sampler.on_silence(lost, &mut push).await;
                        }
                    }
                    Either3::Third(after) => sampler.request_sleep(after, SLEEP.wake),
                }
                publish(&sampler);
            }
            // Dropping the channel disables it.
        }
        let asleep_since = Instant::now();
        POD.set_asleep(true);
        Input::new(int_pin.reborrow(), Pull::None)
            .wait_for_high()
            .await;
        let slept_us = Instant::now().duration_since(asleep_since).as_micros();
        let slept = (slept_us * RATE.millihertz() as u64 / 1_000_000_000) as u32;
        sampler.on_motion(slept, SETTLE, &mut push).await;
        watchdog = Watchdog::new();
        ticker.reset();
        POD.set_asleep(false);
        publish(&sampler);
    }
}

/// The sampler's counters for the status line, and the pipeline task woken.
fn publish(sampler: &ImuSampler<live_settings::AsyncSource<Bus>, Delay>) {
    let c = sampler.counters();
    COUNTERS.lock(|cell| cell.set(c));
    QUEUED.signal(());
}

/// The pipeline and the logs; every stride to the foot pod.
#[embassy_executor::task]
async fn pipeline_task(
    pipeline: &'static mut Pipeline<Steps<MOVEMENT_SAMPLES>>,
    mut consumer: Consumer<'static, Item>,
    mut log: StrideLog,
    mut serial: Serial,
) -> ! {
    let mut drain = Drain::new(&CONFIG, QUEUE_LEN, &SLEEP);
    let status_every = RATE.samples_in_ms(live_app::STATUS_EVERY_MS);
    let mut next_status = status_every;
    loop {
        QUEUED.wait().await;
        drain.run(
            pipeline,
            &mut consumer,
            &mut log,
            &mut serial,
            || COUNTERS.lock(|c| c.get()),
            |s| POD.stride(s, now_ms()),
        );
        if let Some(after) = drain.take_sleep_request() {
            SLEEP_REQUEST.signal(after);
        }
        if drain.samples() >= next_status {
            next_status = next_status.wrapping_add(status_every);
            let (notified, unqueued, connections) = POD.counters();
            let (stack, region) = stack_paint::used_and_size();
            defmt::println!(
                "ble notified={=u32} unqueued={=u32} connections={=u32} total_dm={=u32} stack used={=u32} of {=u32} bytes",
                notified,
                unqueued,
                connections,
                POD.total_distance_dm(),
                stack,
                region
            );
            let _ = serial_line::comment(
                &mut serial,
                format_args!(
                    "ble notified={notified} unqueued={unqueued} connections={connections} total_dm={} stack_used={stack} of {region}",
                    POD.total_distance_dm()
                ),
            );
        }
    }
}

/// The supply voltage (SAADC on VDD) as the battery level, every [`BATTERY_EVERY_S`].
#[embassy_executor::task]
async fn battery_task(mut adc: saadc::Saadc<'static, 1>) -> ! {
    adc.calibrate().await;
    loop {
        let mut raw = [0i16; 1];
        adc.sample(&mut raw).await;
        // Gain 1/6, internal 0.6 V reference, 12 bits: full scale 3.6 V.
        let mv = (raw[0].max(0) as u32 * 3600) / 4096;
        POD.set_battery_percent(battery_percent(mv));
        Timer::after(Duration::from_secs(BATTERY_EVERY_S)).await;
    }
}

#[embassy_executor::task]
async fn ble_task(controller: nrf_sdc::SoftdeviceController<'static>, address: BleAddress) -> ! {
    rsc_gatt::run(controller, address, &POD, &rsc_gatt::DefmtObserver).await
}

/// The static random address from the chip's FICR (its two top bits set, as the Core
/// specification requires of a static address).
fn device_address() -> BleAddress {
    let ficr = pac::FICR;
    let lo = ficr.deviceaddr(0).read().to_le_bytes();
    let hi = ficr.deviceaddr(1).read().to_le_bytes();
    BleAddress::random([lo[0], lo[1], lo[2], lo[3], hi[0], hi[1] | 0xC0])
}

fn build_sdc<'d, const N: usize>(
    p: nrf_sdc::Peripherals<'d>,
    rng: &'d mut rng::Rng<'d, Async>,
    mpsl: &'d MultiprotocolServiceLayer,
    mem: &'d mut sdc::Mem<N>,
) -> Result<nrf_sdc::SoftdeviceController<'d>, nrf_sdc::Error> {
    sdc::Builder::new()?
        .support_adv()
        .support_peripheral()
        .peripheral_count(1)?
        .buffer_cfg(
            DefaultPacketPool::MTU as u16,
            DefaultPacketPool::MTU as u16,
            L2CAP_TXQ,
            L2CAP_RXQ,
        )?
        .build(p, rng, mpsl, mem)
}

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let mut config = embassy_nrf::config::Config::default();
    // Below the SoftDevice Controller's 0 and 1.
    // The DK has the DC/DC converter's inductor: the core and radio draw about half the
    // LDO's current through it (PS v1.11 §5.2). A clip board without it must leave this out.
    config.dcdc.reg1 = true;
    config.gpiote_interrupt_priority = Priority::P2;
    config.time_interrupt_priority = Priority::P2;
    let p = embassy_nrf::init(config);
    for irq in [
        interrupt::TWISPI0,
        interrupt::UARTE0,
        interrupt::SAADC,
        interrupt::RNG,
    ] {
        irq.set_priority(Priority::P5);
    }

    let mut serial = Serial {
        tx: uarte::UarteTx::new(p.UARTE0, Irqs, p.P0_06, uarte::Config::default()),
    };
    let log = StrideLog::new(RATE);
    log.banner("nrf52840-ble", &CONFIG, &mut serial);

    // The SoftDevice Controller, with the LF clock from the internal RC oscillator (the DK
    // has a crystal too; RC keeps the build board-independent, at ±500 ppm).
    let mpsl_p =
        mpsl::Peripherals::new(p.RTC0, p.TIMER0, p.TEMP, p.PPI_CH19, p.PPI_CH30, p.PPI_CH31);
    let lfclk = mpsl::raw::mpsl_clock_lfclk_cfg_t {
        source: mpsl::raw::MPSL_CLOCK_LF_SRC_RC as u8,
        rc_ctiv: mpsl::raw::MPSL_RECOMMENDED_RC_CTIV as u8,
        rc_temp_ctiv: mpsl::raw::MPSL_RECOMMENDED_RC_TEMP_CTIV as u8,
        accuracy_ppm: mpsl::raw::MPSL_DEFAULT_CLOCK_ACCURACY_PPM as u16,
        skip_wait_lfclk_started: mpsl::raw::MPSL_DEFAULT_SKIP_WAIT_LFCLK_STARTED != 0,
    };
    static MPSL: StaticCell<MultiprotocolServiceLayer> = StaticCell::new();
    let mpsl = match mpsl::MultiprotocolServiceLayer::new(mpsl_p, Irqs, lfclk) {
        Ok(m) => MPSL.init(m),
        Err(e) => defmt::panic!("MPSL: {}", e),
    };
    spawner.spawn(mpsl_task(mpsl).unwrap_or_else(|e| defmt::panic!("{}", e)));
    let sdc_p = sdc::Peripherals::new(
        p.PPI_CH17, p.PPI_CH18, p.PPI_CH20, p.PPI_CH21, p.PPI_CH22, p.PPI_CH23, p.PPI_CH24,
        p.PPI_CH25, p.PPI_CH26, p.PPI_CH27, p.PPI_CH28, p.PPI_CH29,
    );
    static RNG_CELL: StaticCell<rng::Rng<'static, Async>> = StaticCell::new();
    let rng = RNG_CELL.init(rng::Rng::new(p.RNG, Irqs));
    static SDC_MEMORY: StaticCell<sdc::Mem<SDC_MEM>> = StaticCell::new();
    let sdc_mem = SDC_MEMORY.init(sdc::Mem::new());
    let controller = match build_sdc(sdc_p, rng, mpsl, sdc_mem) {
        Ok(c) => c,
        Err(e) => defmt::panic!("SoftDevice Controller: {}", e),
    };

    // The sensor, started (and retried) before anything samples it.
    static TX_RAM: ConstStaticCell<[u8; 16]> = ConstStaticCell::new([0; 16]);
    let mut twim_config = twim::Config::default();
    twim_config.frequency = twim::Frequency::K400;
    let bus = Bus {
        twim: twim::Twim::new(
            p.TWISPI0,
            Irqs,
            p.P0_26,
            p.P0_27,
            twim_config,
            TX_RAM.take(),
        ),
    };
    let imu = live_settings::async_source(bus);
    let sampler = live_app::start_async_sensor(imu, Delay, MODE, &mut serial).await;
    let (producer, consumer) = QUEUE.take().split();

    interrupt::EGU1_SWI1.set_priority(Priority::P3);
    let high = SAMPLER_EXECUTOR.start(interrupt::EGU1_SWI1);
    high.spawn(
        sampler_task(sampler, producer, p.GPIOTE_CH0, p.P0_03)
            .unwrap_or_else(|e| defmt::panic!("{}", e)),
    );

    let adc = saadc::Saadc::new(
        p.SAADC,
        Irqs,
        saadc::Config::default(),
        [saadc::ChannelConfig::single_ended(saadc::VddInput)],
    );
    spawner.spawn(battery_task(adc).unwrap_or_else(|e| defmt::panic!("{}", e)));
    spawner.spawn(
        pipeline_task(PIPELINE.take(), consumer, log, serial)
            .unwrap_or_else(|e| defmt::panic!("{}", e)),
    );
    spawner
        .spawn(ble_task(controller, device_address()).unwrap_or_else(|e| defmt::panic!("{}", e)));
}
