//! gaitclip on an nRF52840 (nRF52840-DK pin-out).
//!
//! | MPU6050 | nRF52840-DK | |
//! |---|---|---|
//! | SDA | P0.26 | TWIM0, 400 kHz (4.7 kΩ pull-ups on the breakout) |
//! | SCL | P0.27 | |
//! | INT | P0.03 | GPIOTE channel 0, rising edge |
//! | VCC / GND | VDD / GND | 3.3 V |
//! | serial out | P0.06 (TXD) | UARTE0, 115 200 8N1: the DK's USB virtual COM port |
//!
//! Built with `--features lsm6dsv320x` it samples an LSM6DSV320X on the same pins instead
//! (SA0 to ground, INT1 as INT): 240 Hz, its FIFO read whenever INT1 says it holds its
//! watermark, the high-g channel merged into the accelerometer
//! ([`gaitclip_board::live_settings::lsm6dsv320x`]).
//!
//! The sensor runs at 200 Hz with its FIFO on and pulses INT on every data-ready; the GPIOTE
//! handler counts pulses and reads the FIFO every [`MODE`]'s batch of them in one burst
//! ([`imu_sampler`]), pushing samples into the queue. TIMER1 ticks the sensor watchdog. The
//! main loop runs the pipeline and sleeps (`wfi`). Strides go to defmt over RTT
//! (`probe-rs run`) and, as CSV lines, to the UART.
//!
//! Still for 10 s, the clip sleeps ([`gaitclip_board::sleep`]): the sensor waits for motion
//! in its cycle mode, TIMER1 stops, the crystal oscillator is released (the PMU runs what
//! needs a clock from the internal one) and the core sleeps in System ON until INT. RTC0,
//! on the 32.768 kHz RC oscillator divided to 8 Hz, times the sleep (24 bits: 24 days).

#![no_std]
#![no_main]

use gaitclip_board::{imu_sampler, live_app, stride_log, Steps};

use core::cell::RefCell;

use cortex_m::interrupt::{self as irq, Mutex};
use cortex_m_rt::entry;
use defmt_rtt as _;
use embedded_hal::i2c::{ErrorType, I2c, Operation, SevenBitAddress};
use gaitclip::pipeline::Pipeline;
use gaitclip_board::live_settings::MOVEMENT_SAMPLES;
use heapless::spsc::Queue;
use nrf52840_hal::{
    self as hal,
    gpio::{Floating, Input, Level, OpenDrainConfig, Pin},
    gpiote::Gpiote,
    pac::{self, interrupt, RTC0, TIMER1, TWIM0},
    rtc::Rtc,
    timer::{Periodic, Timer},
    twim::{self, Twim},
    uarte::{self, Uarte},
};
use panic_probe as _;
use static_cell::ConstStaticCell;

use gaitclip_board::live_settings::{self, CONFIG, MODE, QUEUE_LEN, RATE, SLEEP};
use gaitclip_board::sleep::SleepPolicy;
use imu_sampler::{BusRecovery, Item};
use live_app::{IntEvent, SampleLink, SpinDelay, Watchdog, WATCHDOG_TICK_MS};
use stride_log::StrideLog;

/// The core clock, 64 MHz.
const CYCLES_PER_US: u32 = 64;

/// TWIM0 that can give its pins back to clock a stuck bus free.
struct RecoverableTwim {
    twim: Option<Twim<TWIM0>>,
}

impl ErrorType for RecoverableTwim {
    type Error = twim::Error;
}

impl I2c<SevenBitAddress> for RecoverableTwim {
    fn transaction(
        &mut self,
        address: SevenBitAddress,
        operations: &mut [Operation<'_>],
    ) -> Result<(), Self::Error> {
        match self.twim.as_mut() {
            Some(t) => t.transaction(address, operations),
            // Only between `free` and `new` in `recover_bus`, which nothing interrupts.
            None => Err(twim::Error::Transmit),
        }
    }
}

impl BusRecovery for RecoverableTwim {
    fn recover_bus(&mut self) -> bool {
        let Some(twim) = self.twim.take() else {
            return false;
        };
        let (periph, pins) = twim.free();
        let sda = pins.sda;
        let mut scl = pins
            .scl
            .into_open_drain_output(OpenDrainConfig::Standard0Disconnect1, Level::High);
        live_app::clock_bus_free(&mut scl, CYCLES_PER_US);
        let scl: Pin<Input<Floating>> = scl.into_floating_input();
        self.twim = Some(Twim::new(
            periph,
            twim::Pins { scl, sda },
            twim::Frequency::K400,
        ));
        true
    }
}

/// Sampler, queue producer and pulse count, shared by the interrupts and the main loop.
static LINK: SampleLink<live_settings::Source<RecoverableTwim>, SpinDelay> = SampleLink::new();
/// RTC0 at [`SLEEP_CLOCK_HZ`], and its count when the sensor went to sleep.
type SleepClock = (Rtc<RTC0>, u32);
static SLEEP_CLOCK: Mutex<RefCell<Option<SleepClock>>> = Mutex::new(RefCell::new(None));
/// RTC0's rate: 32 768 Hz / (4095 + 1).
const SLEEP_CLOCK_HZ: u32 = 8;
/// Samples dropped after a wake-up while the gyro settles.
const SETTLE: u32 = SleepPolicy::settle_samples(RATE, &SLEEP);
/// GPIOTE and the INT pin it watches.
static GPIOTE: Mutex<RefCell<Option<(Gpiote, IntPin)>>> = Mutex::new(RefCell::new(None));
type IntPin = Pin<Input<Floating>>;
/// TIMER1, ticking the watchdog.
type WatchdogTimer = Timer<TIMER1, Periodic>;
static WATCHDOG: Mutex<RefCell<Option<(WatchdogTimer, Watchdog)>>> = Mutex::new(RefCell::new(None));
static QUEUE: ConstStaticCell<Queue<Item, QUEUE_LEN>> = ConstStaticCell::new(Queue::new());
/// The pipeline's configuration.
static PIPELINE: ConstStaticCell<Pipeline<Steps<MOVEMENT_SAMPLES>>> = ConstStaticCell::new(
    Pipeline::with_detector(CONFIG, Steps::new(&CONFIG.detect())),
);

#[entry]
fn main() -> ! {
    let Some(p) = pac::Peripherals::take() else {
        panic!("peripherals taken twice");
    };
    // The DK has the DC/DC converter's inductor: the core and radio draw about half the
    // LDO's current through it (PS v1.11 §5.2: 3.3 against 6.3 mA at 64 MHz). A clip board
    // without the inductor must leave this out.
    p.POWER.dcdcen.write(|w| w.dcdcen().enabled());
    let _clocks = hal::clocks::Clocks::new(p.CLOCK)
        .enable_ext_hfosc()
        .set_lfclk_src_rc()
        .start_lfclk();
    let Ok(rtc) = Rtc::new(p.RTC0, 4095) else {
        panic!("RTC0 prescaler");
    };
    rtc.enable_counter();
    let port0 = hal::gpio::p0::Parts::new(p.P0);

    let mut serial = Uarte::new(
        p.UARTE0,
        uarte::Pins {
            txd: port0.p0_06.into_push_pull_output(Level::High).degrade(),
            rxd: port0.p0_08.into_floating_input().degrade(),
            cts: None,
            rts: None,
        },
        uarte::Parity::EXCLUDED,
        uarte::Baudrate::BAUD115200,
    );
    let mut log = StrideLog::new(RATE);
    log.banner("nrf52840-dk", &CONFIG, &mut serial);

    let bus = RecoverableTwim {
        twim: Some(Twim::new(
            p.TWIM0,
            twim::Pins {
                scl: port0.p0_27.into_floating_input().degrade(),
                sda: port0.p0_26.into_floating_input().degrade(),
            },
            twim::Frequency::K400,
        )),
    };
    let delay = SpinDelay {
        cycles_per_us: CYCLES_PER_US,
    };
    let imu = live_settings::source(bus);
    let consumer = LINK.start(imu, delay, MODE, QUEUE.take(), &mut serial);
    let int_pin = port0.p0_03.into_floating_input().degrade();
    let gpiote = Gpiote::new(p.GPIOTE);
    gpiote
        .channel0()
        .input_pin(&int_pin)
        .lo_to_hi()
        .enable_interrupt();
    let mut timer = Timer::periodic(p.TIMER1);
    timer.enable_interrupt();
    timer.start(WATCHDOG_TICK_MS * 1000); // 1 MHz timer clock
    irq::free(|cs| {
        GPIOTE.borrow(cs).replace(Some((gpiote, int_pin)));
        WATCHDOG.borrow(cs).replace(Some((timer, Watchdog::new())));
        SLEEP_CLOCK.borrow(cs).replace(Some((rtc, 0)));
    });
    // Note(unsafe): both handlers only touch state behind `Mutex`es and atomics, so
    // unmasking cannot break a critical section.
    unsafe {
        pac::NVIC::unmask(pac::Interrupt::GPIOTE);
        pac::NVIC::unmask(pac::Interrupt::TIMER1);
    }

    LINK.main_loop(
        PIPELINE.take(),
        &CONFIG,
        consumer,
        &mut log,
        &mut serial,
        &SLEEP,
    )
}

#[interrupt]
fn GPIOTE() {
    irq::free(|cs| {
        if let Some((g, _)) = GPIOTE.borrow(cs).borrow().as_ref() {
            g.reset_events();
        }
    });
    irq::free(|cs| {
        let mut clock = SLEEP_CLOCK.borrow(cs).borrow_mut();
        let Some((rtc, asleep_at)) = clock.as_mut() else {
            LINK.on_data_ready();
            return;
        };
        let now = rtc.get_counter();
        // 24-bit counter: the difference modulo 2²⁴ ticks of 125 ms, 25 periods each at
        // 200 Hz (at most 4.2·10⁸: fits).
        let slept = || {
            let ticks = (now.wrapping_sub(*asleep_at) & 0xFF_FFFF) as u64;
            (ticks * RATE.millihertz() as u64 / 1000 / SLEEP_CLOCK_HZ as u64) as u32
        };
        match LINK.on_int(SETTLE, slept) {
            IntEvent::FellAsleep => {
                *asleep_at = now;
                set_awake_clocks(cs, false);
                watch_int(cs, false);
            }
            IntEvent::Woke => {
                watch_int(cs, true);
                set_awake_clocks(cs, true);
            }
            IntEvent::Sampled => {}
        }
    });
}

/// Watches INT with channel 0's rising-edge event while sampling (it catches the 50 µs
/// data-ready pulses), and with the PORT event on the pin's level while asleep: an IN
/// channel in event mode keeps a high-frequency clock requested, the pin's SENSE does not,
/// and the latched motion interrupt is a level the SENSE cannot miss.
fn watch_int(cs: &irq::CriticalSection, sampling: bool) {
    let gpiote = GPIOTE.borrow(cs).borrow();
    let Some((g, pin)) = gpiote.as_ref() else {
        return;
    };
    if sampling {
        g.port().disable_interrupt();
        g.port().input_pin(pin).disabled();
        g.channel0().input_pin(pin).lo_to_hi().enable_interrupt();
    } else {
        g.channel0().input_pin(pin).none().disable_interrupt();
        // Note(unsafe): only this handler and `main` (before the interrupts were unmasked)
        // touch GPIOTE; writing CONFIG[0] is a plain register write, MODE = disabled frees
        // the channel (the HAL has no call for it).
        let raw = unsafe { &*pac::GPIOTE::ptr() };
        raw.config[0].write(|w| w.mode().disabled());
        g.port().input_pin(pin).high();
        g.port().enable_interrupt();
    }
}

/// Stops (asleep) or starts (awake) what only sampling needs: TIMER1's watchdog ticks and
/// the crystal oscillator.
fn set_awake_clocks(cs: &irq::CriticalSection, awake: bool) {
    if let Some((timer, watchdog)) = WATCHDOG.borrow(cs).borrow_mut().as_mut() {
        if awake {
            *watchdog = Watchdog::new();
            timer.start(WATCHDOG_TICK_MS * 1000);
        } else {
            // Note(unsafe): TASKS_STOP is a write-only trigger; 1 is its one value.
            timer.task_stop().write(|w| unsafe { w.bits(1) });
        }
    }
    // Note(unsafe): CLOCK's HFCLKSTART/HFCLKSTOP are write-only triggers (1 starts or stops
    // the crystal); nothing else touches them after `main` set the clocks up, and the PMU
    // keeps the internal oscillator for whatever needs a clock meanwhile.
    let clock = unsafe { &*pac::CLOCK::ptr() };
    if awake {
        clock.tasks_hfclkstart.write(|w| unsafe { w.bits(1) });
    } else {
        clock.tasks_hfclkstop.write(|w| unsafe { w.bits(1) });
    }
}

#[interrupt]
fn TIMER1() {
    irq::free(|cs| {
        let mut wd = WATCHDOG.borrow(cs).borrow_mut();
        if let Some((timer, watchdog)) = wd.as_mut() {
            timer.reset_event();
            LINK.on_watchdog_tick(watchdog, RATE.samples_in_ms(WATCHDOG_TICK_MS));
        }
    });
}
