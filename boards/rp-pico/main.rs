//! gaitclip on a Raspberry Pi Pico (RP2040: Cortex-M0+, no FPU).
//!
//! | MPU6050 | Pico | |
//! |---|---|---|
//! | SDA | GP4 (pin 6) | I2C0, 400 kHz, internal pull-ups (plus the breakout's) |
//! | SCL | GP5 (pin 7) | |
//! | INT | GP6 (pin 9) | rising edge, IO_IRQ_BANK0 |
//! | VCC / GND | 3V3(OUT) (pin 36) / GND (pin 38) | |
//! | serial out | GP0 (pin 1, UART0 TX) | 115 200 8N1, to a USB-serial adapter's RX |
//!
//! Built with `--features lsm6dsv320x` it samples an LSM6DSV320X on the same pins instead
//! (SA0 to ground, INT1 as INT): 240 Hz, its FIFO read whenever INT1 says it holds its
//! watermark, the high-g channel merged into the accelerometer
//! ([`gaitclip_board::live_settings::lsm6dsv320x`]).
//!
//! Same firmware as the nRF52840 board: FIFO bursts on data-ready pulses, the shared sampler
//! with retries, bus recovery and re-initialisation, the TIMER alarm as the sensor
//! watchdog, the pipeline in the main loop with `wfi`, strides on defmt-RTT and the UART.
//!
//! Still for 10 s, the clip sleeps ([`gaitclip_board::sleep`]): the sensor waits for motion
//! in its cycle mode and the watchdog alarm is not rearmed; the TIMER's microsecond count
//! times the sleep. The core only waits in `wfi` with its clocks running: the RP2040's
//! DORMANT state (0.18 mA typical, datasheet §5.7.2, Table 637) needs the clocks stopped and
//! rebuilt around it, which this build does not do (docs/energy.md).

#![no_std]
#![no_main]

use gaitclip_board::{imu_sampler, live_app, stride_log, Steps};

use core::cell::RefCell;

use cortex_m::interrupt::{self as irq, Mutex};
use defmt_rtt as _;
use embedded_hal::i2c::{ErrorType, I2c, Operation, SevenBitAddress};
use fugit::{HertzU32, RateExtU32};
use gaitclip::pipeline::Pipeline;
use gaitclip_board::live_settings::MOVEMENT_SAMPLES;
use heapless::spsc::Queue;
use panic_probe as _;
use rp2040_hal::{
    self as hal,
    clocks::{init_clocks_and_plls, Clock},
    gpio::{
        bank0::{Gpio4, Gpio5, Gpio6},
        FunctionI2C, FunctionSioInput, FunctionUart, Interrupt as PinInterrupt, Pin, Pins,
        PullDown, PullUp,
    },
    pac::{self, interrupt},
    timer::{Alarm, Alarm0},
    uart::{DataBits, StopBits, UartConfig, UartPeripheral},
    Sio, Timer, Watchdog,
};
use static_cell::ConstStaticCell;

use gaitclip_board::live_settings::{self, CONFIG, MODE, QUEUE_LEN, RATE, SLEEP};
use gaitclip_board::sleep::SleepPolicy;
use imu_sampler::{BusRecovery, Item};
use live_app::{IntEvent, SampleLink, SpinDelay, Watchdog as SensorWatchdog, WATCHDOG_TICK_MS};
use stride_log::StrideLog;

/// The second-stage bootloader for the Pico's W25Q080 flash.
#[link_section = ".boot2"]
#[used]
pub static BOOT2: [u8; 256] = rp2040_boot2::BOOT_LOADER_W25Q080;

/// The Pico's crystal.
const XOSC_HZ: u32 = 12_000_000;
/// The system clock, 125 MHz.
const CYCLES_PER_US: u32 = 125;

type Sda = Pin<Gpio4, FunctionI2C, PullUp>;
type Scl = Pin<Gpio5, FunctionI2C, PullUp>;
type Bus = hal::I2C<pac::I2C0, (Sda, Scl)>;
type IntPin = Pin<Gpio6, FunctionSioInput, PullDown>;

/// I2C0 that can give its pins back to clock a stuck bus free.
struct RecoverableI2c {
    i2c: Option<Bus>,
    resets: pac::RESETS,
    system_clock: HertzU32,
}

impl ErrorType for RecoverableI2c {
    type Error = hal::i2c::Error;
}

impl I2c<SevenBitAddress> for RecoverableI2c {
    fn transaction(
        &mut self,
        address: SevenBitAddress,
        operations: &mut [Operation<'_>],
    ) -> Result<(), Self::Error> {
        match self.i2c.as_mut() {
            Some(i2c) => i2c.transaction(address, operations),
            // Only between `free` and `i2c0` in `recover_bus`, which nothing interrupts.
            None => Err(hal::i2c::Error::Abort(0)),
        }
    }
}

impl BusRecovery for RecoverableI2c {
    fn recover_bus(&mut self) -> bool {
        let Some(i2c) = self.i2c.take() else {
            return false;
        };
        let (block, (sda, scl)) = i2c.free(&mut self.resets);
        let mut scl = scl.into_push_pull_output();
        live_app::clock_bus_free(&mut scl, CYCLES_PER_US);
        let scl: Scl = scl.into_function();
        self.i2c = Some(hal::I2C::i2c0(
            block,
            sda,
            scl,
            400.kHz(),
            &mut self.resets,
            self.system_clock,
        ));
        true
    }
}

/// Sampler, queue producer and pulse count, shared by the interrupts and the main loop.
static LINK: SampleLink<live_settings::Source<RecoverableI2c>, SpinDelay> = SampleLink::new();
static INT_PIN: Mutex<RefCell<Option<IntPin>>> = Mutex::new(RefCell::new(None));
static WATCHDOG: Mutex<RefCell<Option<(Alarm0, SensorWatchdog)>>> = Mutex::new(RefCell::new(None));
/// The TIMER, and its count (µs) when the sensor went to sleep.
static SLEEP_CLOCK: Mutex<RefCell<Option<(Timer, u64)>>> = Mutex::new(RefCell::new(None));
/// Samples dropped after a wake-up while the gyro settles.
const SETTLE: u32 = SleepPolicy::settle_samples(RATE, &SLEEP);
static QUEUE: ConstStaticCell<Queue<Item, QUEUE_LEN>> = ConstStaticCell::new(Queue::new());
/// The pipeline's configuration.
static PIPELINE: ConstStaticCell<Pipeline<Steps<MOVEMENT_SAMPLES>>> = ConstStaticCell::new(
    Pipeline::with_detector(CONFIG, Steps::new(&CONFIG.detect())),
);

#[hal::entry]
fn main() -> ! {
    let Some(mut pac) = pac::Peripherals::take() else {
        panic!("peripherals taken twice");
    };
    let mut watchdog = Watchdog::new(pac.WATCHDOG);
    let Ok(clocks) = init_clocks_and_plls(
        XOSC_HZ,
        pac.XOSC,
        pac.CLOCKS,
        pac.PLL_SYS,
        pac.PLL_USB,
        &mut pac.RESETS,
        &mut watchdog,
    ) else {
        panic!("clocks did not start");
    };
    let sio = Sio::new(pac.SIO);
    let pins = Pins::new(
        pac.IO_BANK0,
        pac.PADS_BANK0,
        sio.gpio_bank0,
        &mut pac.RESETS,
    );

    let uart_pins = (
        pins.gpio0.into_function::<FunctionUart>(),
        pins.gpio1.into_function::<FunctionUart>(),
    );
    let Ok(mut serial) = UartPeripheral::new(pac.UART0, uart_pins, &mut pac.RESETS).enable(
        UartConfig::new(115_200.Hz(), DataBits::Eight, None, StopBits::One),
        clocks.peripheral_clock.freq(),
    ) else {
        panic!("UART0 did not start");
    };
    let mut log = StrideLog::new(RATE);
    log.banner("rp-pico", &CONFIG, &mut serial);

    let sda: Sda = pins.gpio4.reconfigure();
    let scl: Scl = pins.gpio5.reconfigure();
    let system_clock = clocks.system_clock.freq();
    let mut timer = Timer::new(pac.TIMER, &mut pac.RESETS, &clocks);
    let i2c = hal::I2C::i2c0(pac.I2C0, sda, scl, 400.kHz(), &mut pac.RESETS, system_clock);
    let bus = RecoverableI2c {
        i2c: Some(i2c),
        resets: pac.RESETS,
        system_clock,
    };
    let delay = SpinDelay {
        cycles_per_us: CYCLES_PER_US,
    };
    let imu = live_settings::source(bus);
    let consumer = LINK.start(imu, delay, MODE, QUEUE.take(), &mut serial);
    let int_pin: IntPin = pins.gpio6.into_pull_down_input();
    int_pin.set_interrupt_enabled(PinInterrupt::EdgeHigh, true);
    let Some(mut alarm) = timer.alarm_0() else {
        panic!("alarm 0 taken");
    };
    let _ = alarm.schedule(fugit::MicrosDurationU32::millis(WATCHDOG_TICK_MS));
    alarm.enable_interrupt();
    irq::free(|cs| {
        INT_PIN.borrow(cs).replace(Some(int_pin));
        WATCHDOG
            .borrow(cs)
            .replace(Some((alarm, SensorWatchdog::new())));
        SLEEP_CLOCK.borrow(cs).replace(Some((timer, 0)));
    });
    // Note(unsafe): both handlers only touch state behind `Mutex`es and atomics, so
    // unmasking cannot break a critical section.
    unsafe {
        pac::NVIC::unmask(pac::Interrupt::IO_IRQ_BANK0);
        pac::NVIC::unmask(pac::Interrupt::TIMER_IRQ_0);
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
fn IO_IRQ_BANK0() {
    irq::free(|cs| {
        if let Some(pin) = INT_PIN.borrow(cs).borrow_mut().as_mut() {
            pin.clear_interrupt(PinInterrupt::EdgeHigh);
        }
    });
    irq::free(|cs| {
        let mut clock = SLEEP_CLOCK.borrow(cs).borrow_mut();
        let Some((timer, asleep_at)) = clock.as_mut() else {
            LINK.on_data_ready();
            return;
        };
        let now = timer.get_counter().ticks();
        let slept = || {
            let us = now.saturating_sub(*asleep_at);
            (us * RATE.millihertz() as u64 / 1_000_000_000).min(u32::MAX as u64) as u32
        };
        match LINK.on_int(SETTLE, slept) {
            IntEvent::FellAsleep => *asleep_at = now,
            IntEvent::Woke => {
                // The watchdog starts over, its alarm rearmed.
                if let Some((alarm, watchdog)) = WATCHDOG.borrow(cs).borrow_mut().as_mut() {
                    *watchdog = SensorWatchdog::new();
                    let _ = alarm.schedule(fugit::MicrosDurationU32::millis(WATCHDOG_TICK_MS));
                }
            }
            IntEvent::Sampled => {}
        }
    });
}

#[interrupt]
fn TIMER_IRQ_0() {
    irq::free(|cs| {
        let mut wd = WATCHDOG.borrow(cs).borrow_mut();
        if let Some((alarm, watchdog)) = wd.as_mut() {
            alarm.clear_interrupt();
            if LINK.asleep() {
                // Not rearmed while the sensor sleeps: INT rearms it on waking.
                return;
            }
            let _ = alarm.schedule(fugit::MicrosDurationU32::millis(WATCHDOG_TICK_MS));
            LINK.on_watchdog_tick(watchdog, RATE.samples_in_ms(WATCHDOG_TICK_MS));
        }
    });
}
