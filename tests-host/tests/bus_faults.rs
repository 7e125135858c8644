//! Bus faults injected with `embedded-hal-mock`, every transaction spelled out: NACKs,
//! timeouts, a wrong `WHO_AM_I`, and a sensor that stops answering mid-walk and comes back.
//! The firmware's sampler (`boards/common/imu_sampler.rs`) counts and retries each failure,
//! recovers the bus and re-initialises the sensor, reports the lost periods as a gap, and the
//! pipeline reports the stride across the outage as invalid (a gap stride) and resumes: the
//! strides before it are unchanged, the ones after it all found. No panic anywhere.
//!
//! Every scenario runs through both samplers, the blocking one of the bare-metal boards and
//! the async one of the embassy board (`imu_sampler::asynch`), over the same script: the
//! same transactions, items and counters.

use embedded_hal::i2c::{ErrorKind, ErrorType, I2c, NoAcknowledgeSource, Operation};
use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::i2c::{Mock, Transaction as T};
use gaitclip::pipeline::Pipeline;
use gaitclip::record::stride::{Stride, StrideFlags};
use gaitclip::sensor::rate::SampleRate;
use gaitclip_board::imu_sampler::{self, asynch};
use gaitclip_mpu6050::blocking::{Mpu6050, Mpu6050Source};
use gaitclip_mpu6050::{AccelRange, GyroRange};
use gaitclip_mpu6050::{Address, Config, OutputRate};
use imu_sampler::{BusRecovery, Counters, ImuSampler, Item, ReadMode, RESTART_AFTER, RETRIES};

// Register map (MPU-6000/6050 Register Map rev. 4.2), not imported from the driver.
const ADDR: u8 = 0x68;
const SMPLRT_DIV: u8 = 0x19;
const CONFIG: u8 = 0x1A;
const GYRO_CONFIG: u8 = 0x1B;
const ACCEL_CONFIG: u8 = 0x1C;
const INT_PIN_CFG: u8 = 0x37;
const INT_ENABLE: u8 = 0x38;
const INT_STATUS: u8 = 0x3A;
const ACCEL_XOUT_H: u8 = 0x3B;
const FIFO_EN: u8 = 0x23;
const USER_CTRL: u8 = 0x6A;
const FIFO_COUNT_H: u8 = 0x72;
const FIFO_R_W: u8 = 0x74;
const PWR_MGMT_1: u8 = 0x6B;
const WHO_AM_I: u8 = 0x75;

const NACK: ErrorKind = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
/// What HALs report for a clock-stretch or transfer timeout: embedded-hal has no kind of its
/// own for it.
const TIMEOUT: ErrorKind = ErrorKind::Other;

/// The mocked bus; the board's SCL recovery always succeeds (the sampler counts it).
struct Bus {
    mock: Mock,
}

impl ErrorType for Bus {
    type Error = ErrorKind;
}

impl I2c for Bus {
    fn read(&mut self, a: u8, b: &mut [u8]) -> Result<(), ErrorKind> {
        self.mock.read(a, b)
    }
    fn write(&mut self, a: u8, b: &[u8]) -> Result<(), ErrorKind> {
        self.mock.write(a, b)
    }
    fn write_read(&mut self, a: u8, w: &[u8], r: &mut [u8]) -> Result<(), ErrorKind> {
        self.mock.write_read(a, w, r)
    }
    fn transaction(&mut self, a: u8, ops: &mut [Operation<'_>]) -> Result<(), ErrorKind> {
        self.mock.transaction(a, ops)
    }
}

/// The same mock on the async side: every method forwarded, so the script reads the same.
impl embedded_hal_async::i2c::I2c for Bus {
    async fn read(&mut self, a: u8, b: &mut [u8]) -> Result<(), ErrorKind> {
        embedded_hal_async::i2c::I2c::read(&mut self.mock, a, b).await
    }
    async fn write(&mut self, a: u8, b: &[u8]) -> Result<(), ErrorKind> {
        embedded_hal_async::i2c::I2c::write(&mut self.mock, a, b).await
    }
    async fn write_read(&mut self, a: u8, w: &[u8], r: &mut [u8]) -> Result<(), ErrorKind> {
        embedded_hal_async::i2c::I2c::write_read(&mut self.mock, a, w, r).await
    }
    async fn transaction(&mut self, a: u8, ops: &mut [Operation<'_>]) -> Result<(), ErrorKind> {
        embedded_hal_async::i2c::I2c::transaction(&mut self.mock, a, ops).await
    }
}

impl BusRecovery for Bus {
    fn recover_bus(&mut self) -> bool {
        true
    }
}

/// The expected transactions, written as the sampler must issue them.
#[derive(Default)]
struct Script(Vec<T>);

impl Script {
    /// Set-up at 200 Hz, ±16 g, ±2000 °/s, data-ready interrupt latched.
    fn init(&mut self) {
        self.0.extend([
            T::write_read(ADDR, vec![WHO_AM_I], vec![0x68]),
            T::write(ADDR, vec![PWR_MGMT_1, 0x80]),
            T::write(ADDR, vec![PWR_MGMT_1, 0x01]),
            T::write(ADDR, vec![SMPLRT_DIV, 4]),
            T::write(ADDR, vec![CONFIG, 2]),
            T::write(ADDR, vec![GYRO_CONFIG, 3 << 3]),
            T::write(ADDR, vec![ACCEL_CONFIG, 3 << 3]),
            T::write(ADDR, vec![INT_PIN_CFG, 0x30]),
            T::write(ADDR, vec![INT_ENABLE, 0x11]),
        ]);
    }
    /// Set-up in FIFO mode: the same registers, then the FIFO and a pulsed interrupt.
    fn init_fifo(&mut self) {
        self.init();
        self.0.truncate(self.0.len() - 2);
        self.0.extend([
            T::write(ADDR, vec![USER_CTRL, 0x04]),
            T::write(ADDR, vec![FIFO_EN, 0xF8]),
            T::write(ADDR, vec![USER_CTRL, 0x40]),
            T::write(ADDR, vec![INT_PIN_CFG, 0x00]),
            T::write(ADDR, vec![INT_ENABLE, 0x01]),
        ]);
    }
    /// A FIFO burst holding `samples`.
    fn fifo(&mut self, samples: &[[u8; 14]]) {
        let bytes = (samples.len() * 14) as u16;
        self.0.extend([
            T::write_read(ADDR, vec![INT_STATUS], vec![0x01]),
            T::write_read(ADDR, vec![FIFO_COUNT_H], bytes.to_be_bytes().to_vec()),
        ]);
        for x in samples {
            self.0.push(T::write_read(ADDR, vec![FIFO_R_W], x.to_vec()));
        }
    }
    /// A FIFO read that finds the overflow flag: the FIFO is reset.
    fn fifo_overflowed(&mut self) {
        self.0.extend([
            T::write_read(ADDR, vec![INT_STATUS], vec![0x11]),
            T::write(ADDR, vec![USER_CTRL, 0x44]),
        ]);
    }
    /// A set-up that stops at the probe: no answer.
    fn init_unanswered(&mut self) {
        self.0
            .push(T::write_read(ADDR, vec![WHO_AM_I], vec![0]).with_error(NACK));
    }
    /// A set-up that stops at the probe: another part answers.
    fn init_wrong_device(&mut self, who: u8) {
        self.0.push(T::write_read(ADDR, vec![WHO_AM_I], vec![who]));
    }
    fn read(&mut self, sample: &[u8]) {
        self.0
            .push(T::write_read(ADDR, vec![ACCEL_XOUT_H], sample.to_vec()));
    }
    fn read_fails(&mut self, kind: ErrorKind) {
        self.0
            .push(T::write_read(ADDR, vec![ACCEL_XOUT_H], vec![0; 14]).with_error(kind));
    }
}

/// Which sampler a scenario runs through.
#[derive(Clone, Copy, Debug)]
enum Flavor {
    Blocking,
    Async,
}

const FLAVORS: [Flavor; 2] = [Flavor::Blocking, Flavor::Async];

/// Either sampler behind one face; the async one's futures run to completion at once
/// (the mock never makes them wait).
enum Sampler {
    Blocking(ImuSampler<Mpu6050Source<Bus>, NoopDelay>),
    Async(asynch::ImuSampler<gaitclip_mpu6050::asynch::Mpu6050Source<Bus>, NoopDelay>),
}

impl Sampler {
    /// Starts the sensor over `script`; the mock's handle, to check it was all used.
    fn start(flavor: Flavor, script: &Script, mode: ReadMode) -> (Mock, Sampler) {
        let mock = Mock::new(&script.0);
        let bus = Bus { mock: mock.clone() };
        let config = Config::new(OutputRate::from_hz(200).unwrap());
        let sampler = match flavor {
            Flavor::Blocking => ImuSampler::start(
                Mpu6050Source::new(Mpu6050::new(bus, Address::Ad0Low), config),
                NoopDelay,
                mode,
            )
            .map(Sampler::Blocking)
            .ok(),
            Flavor::Async => futures_executor::block_on(asynch::ImuSampler::start(
                gaitclip_mpu6050::asynch::Mpu6050Source::new(
                    gaitclip_mpu6050::asynch::Mpu6050::new(bus, Address::Ad0Low),
                    config,
                ),
                NoopDelay,
                mode,
            ))
            .map(Sampler::Async)
            .ok(),
        };
        let Some(sampler) = sampler else {
            panic!("the sensor starts ({flavor:?})");
        };
        (mock, sampler)
    }

    fn on_data_ready(&mut self, push: &mut impl FnMut(Item) -> bool) {
        match self {
            Sampler::Blocking(s) => s.on_data_ready(push),
            Sampler::Async(s) => futures_executor::block_on(s.on_data_ready(push)),
        }
    }

    fn on_silence(&mut self, periods: u32, push: &mut impl FnMut(Item) -> bool) {
        match self {
            Sampler::Blocking(s) => s.on_silence(periods, push),
            Sampler::Async(s) => futures_executor::block_on(s.on_silence(periods, push)),
        }
    }

    fn counters(&self) -> Counters {
        match self {
            Sampler::Blocking(s) => s.counters(),
            Sampler::Async(s) => s.counters(),
        }
    }
}

fn trace() -> Vec<[u8; 14]> {
    let bytes = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/demo_walk.mpu6050"),
    )
    .unwrap();
    bytes
        .chunks_exact(14)
        .map(|c| c.try_into().unwrap())
        .collect()
}

/// Runs one data-ready pulse per entry of `pulses` through the sampler and every item
/// through the pipeline, as the firmware's main loop does; checks the bus saw exactly the
/// script.
fn run(flavor: Flavor, script: &Script, pulses: usize) -> (Vec<Stride>, Vec<Item>, Counters) {
    let (mut mock, mut sampler) = Sampler::start(flavor, script, ReadMode::PerSample);
    let rate = SampleRate::from_hz(200).unwrap();
    let mut p = Pipeline::new(gaitclip::pipeline::config::Config::new(
        rate,
        AccelRange::G16.scale(),
        GyroRange::Dps2000.scale(),
    ));
    let (mut items, mut strides) = (Vec::new(), Vec::new());
    for _ in 0..pulses {
        sampler.on_data_ready(&mut |i| {
            items.push(i);
            true
        });
    }
    for i in &items {
        strides.extend(i.feed(&mut p));
    }
    strides.extend(std::iter::from_fn(|| p.finish()));
    // The clone shares the expectations: every scripted transaction happened, no more.
    mock.done();
    (strides, items, sampler.counters())
}

/// The demo walk read cleanly: the reference.
fn clean(n: usize) -> Vec<Stride> {
    let t = trace();
    let mut s = Script::default();
    s.init();
    for x in &t[..n] {
        s.read(x);
    }
    run(Flavor::Blocking, &s, n).0
}

#[test]
fn nacks_and_timeouts_are_retried_and_lose_nothing() {
    let t = trace();
    let n = t.len();
    let mut s = Script::default();
    s.init();
    for (k, x) in t.iter().enumerate() {
        match k % 500 {
            // A NACK, then the retry reads it.
            100 => s.read_fails(NACK),
            // Two timeouts in a row, the last retry reads it.
            300 => {
                s.read_fails(TIMEOUT);
                s.read_fails(TIMEOUT);
            }
            _ => {}
        }
        s.read(x);
    }
    let nacks = (0..n).filter(|k| k % 500 == 100).count() as u32;
    let timeouts = 2 * (0..n).filter(|k| k % 500 == 300).count() as u32;
    let reference = clean(n);
    for flavor in FLAVORS {
        let (strides, items, c) = run(flavor, &s, n);
        assert_eq!(c.bus_errors, nacks + timeouts, "{flavor:?} {c:?}");
        assert_eq!(
            (c.lost_samples, c.restarts, c.recoveries),
            (0, 0, 0),
            "{flavor:?} {c:?}"
        );
        assert!(items.iter().all(|i| matches!(i, Item::Sample(_))));
        assert_eq!(
            strides, reference,
            "{flavor:?}: retried reads give the same strides"
        );
    }
}

#[test]
fn a_sensor_that_stops_mid_walk_is_restarted_and_its_stride_marked() {
    let t = trace();
    let n = t.len();
    let reference = clean(n);
    // Stop in the swing of a stride in the middle of the walk.
    let mid = reference[reference.len() / 2];
    let stop = ((mid.events.toe_off + mid.events.heel_strike) / 2) as usize;
    // Out for OUT periods: each read fails all its attempts; from the RESTART_AFTER-th
    // failed period on, each one recovers the bus and tries a set-up: the first finds
    // nobody, the second a part that is not an MPU6050 (the bus still settling), the third
    // the sensor, back.
    const OUT: usize = RESTART_AFTER as usize + 2;
    let mut s = Script::default();
    s.init();
    for x in &t[..stop] {
        s.read(x);
    }
    for period in 1..=OUT {
        for _ in 0..=RETRIES {
            s.read_fails(NACK);
        }
        match period.checked_sub(RESTART_AFTER as usize) {
            Some(0) => s.init_unanswered(),
            Some(1) => s.init_wrong_device(0x70),
            Some(_) => s.init(),
            None => {}
        }
    }
    // The sensor answers again; the samples of the outage are gone.
    for x in &t[stop + OUT..] {
        s.read(x);
    }
    for flavor in FLAVORS {
        let (strides, items, c) = run(flavor, &s, n);
        assert_eq!(
            c.bus_errors,
            (OUT as u32) * (RETRIES + 1) + 2,
            "{flavor:?} {c:?}"
        );
        assert_eq!((c.restarts, c.recoveries), (1, 3), "{flavor:?} {c:?}");
        assert_eq!(c.lost_samples, OUT as u32, "{flavor:?} {c:?}");
        // Every pulse is a sample or part of a gap; the gap is where the outage was.
        let gaps: Vec<(usize, u32)> = items
            .iter()
            .enumerate()
            .filter_map(|(k, i)| match i {
                Item::Gap(g) => Some((k, *g)),
                Item::Sample(_) | Item::Asleep | Item::Woke(_) => None,
            })
            .collect();
        assert_eq!(gaps, vec![(stop, OUT as u32)]);
        assert_eq!(items.len() - 1, n - OUT);
        // The stride across the outage (25 ms: longer than the bridge limit, short enough to
        // fill): reported once, a gap stride without a measured length, at its place, its
        // length estimated from the two measured gait cycles before it.
        const {
            assert!(
                OUT as u32 * 5 > gaitclip::pipeline::config::BRIDGE_MAX_MS
                    && OUT as u32 * 5 <= gaitclip::pipeline::config::FILL_MAX_MS
            )
        };
        let gap: Vec<&Stride> = strides
            .iter()
            .filter(|s| s.flags.has(StrideFlags::GAP))
            .collect();
        assert_eq!(gap.len(), 1, "{strides:#?}");
        assert_eq!(
            (gap[0].events.start, gap[0].events.end),
            (mid.events.start, mid.events.end)
        );
        let cycles: Vec<u32> = strides
            .iter()
            .take_while(|s| s.index < gap[0].index)
            .filter(|s| {
                s.flags.valid()
                    && !s
                        .flags
                        .has(StrideFlags::FROM_REST | StrideFlags::TO_REST | StrideFlags::GAP)
            })
            .map(|s| s.length_mm)
            .collect();
        let last_two = &cycles[cycles.len().saturating_sub(2)..];
        assert_eq!(last_two.len(), 2, "{strides:#?}");
        assert!(
            !gap[0].flags.valid()
                && gap[0].flags.has(StrideFlags::ESTIMATED)
                && gap[0].flags.counts_distance()
                && gap[0].length_mm == (last_two[0] + last_two[1]).div_ceil(2),
            "{:?} after {last_two:?}",
            gap[0]
        );
        // Before it, nothing changed; after it, every stride is found again at the same place.
        assert_eq!(strides.len(), reference.len());
        for (a, b) in reference.iter().zip(&strides) {
            if a.events.end < mid.events.start {
                assert_eq!(a, b);
            } else if a.events.start > mid.events.end {
                assert_eq!(
                    (a.events.start, a.events.end),
                    (b.events.start, b.events.end)
                );
                assert!(a.zupt_um.abs_diff(b.zupt_um) <= 10_000, "{a:?} vs {b:?}");
                assert!(b.flags.valid() == a.flags.valid(), "{a:?} vs {b:?}");
            }
        }
    }
}

/// The sampler in FIFO mode over the mock, batch of 4 pulses per read.
fn fifo_sampler(flavor: Flavor, script: &Script) -> (Mock, Sampler) {
    Sampler::start(flavor, script, ReadMode::Fifo { batch: 4 })
}

#[test]
fn a_fifo_overflow_becomes_a_gap_of_what_it_cost() {
    let t = trace();
    let mut s = Script::default();
    s.init_fifo();
    s.fifo(&t[0..4]);
    // At the next read (pulse 8) the FIFO had overflowed (reads held off, a glitch on the
    // bus): it is reset, and the four samples pulsed since the last read are lost.
    s.fifo_overflowed();
    s.fifo(&t[8..12]);
    for flavor in FLAVORS {
        let (mut mock, mut sampler) = fifo_sampler(flavor, &s);
        let mut items = Vec::new();
        for _ in 0..12 {
            sampler.on_data_ready(&mut |i| {
                items.push(i);
                true
            });
        }
        mock.done();
        let c = sampler.counters();
        assert_eq!(
            (c.fifo_overflows, c.lost_samples, c.bus_errors),
            (1, 4, 0),
            "{flavor:?} {c:?}"
        );
        let want: Vec<Item> = t[0..4]
            .iter()
            .map(|x| Item::Sample(gaitclip_mpu6050::sample::from_be_bytes(x)))
            .chain([Item::Gap(4)])
            .chain(
                t[8..12]
                    .iter()
                    .map(|x| Item::Sample(gaitclip_mpu6050::sample::from_be_bytes(x))),
            )
            .collect();
        assert_eq!(items, want);
    }
}

#[test]
fn a_silent_sensor_found_by_the_watchdog_is_set_up_again_and_the_silence_is_a_gap() {
    let t = trace();
    let mut s = Script::default();
    s.init_fifo();
    s.fifo(&t[0..4]);
    // 60 periods without a pulse (the sensor browned out); the watchdog calls on_silence:
    // the bus is recovered and the sensor set up again.
    s.init_fifo();
    s.fifo(&t[70..74]);
    for flavor in FLAVORS {
        let (mut mock, mut sampler) = fifo_sampler(flavor, &s);
        let mut items = Vec::new();
        let mut push = |i| {
            items.push(i);
            true
        };
        for _ in 0..6 {
            sampler.on_data_ready(&mut push);
        }
        // Two pulses were counted but never read: they are part of the silence's gap.
        sampler.on_silence(60, &mut push);
        for _ in 0..4 {
            sampler.on_data_ready(&mut push);
        }
        mock.done();
        let c = sampler.counters();
        assert_eq!(
            (c.silences, c.restarts, c.recoveries, c.lost_samples),
            (1, 1, 1, 62),
            "{flavor:?} {c:?}"
        );
        assert_eq!(items.len(), 4 + 1 + 4);
        assert_eq!(items[4], Item::Gap(62));
    }
}
