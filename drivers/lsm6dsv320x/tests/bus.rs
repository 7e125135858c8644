//! The bus driver against a mocked bus, every transaction spelt out. The registers and values
//! below are written from ST's register map as `lsm6dsv320x-rs` 2.x gives it
//! (`src/register/main.rs`: addresses, field positions, enum codes) and its reset procedure
//! (`sw_reset`), not imported from this crate. Each case runs on the blocking driver and, from
//! the same source, on the async one (`block_on` stands in for the board's executor).

use embedded_hal_mock::eh1::i2c::Transaction as T;

const ADDR: u8 = 0x6A; // SA0 low
const WHO_AM_I: u8 = 0x0F; // reads 0x73
const FIFO_CTRL1: u8 = 0x07;
const FIFO_CTRL3: u8 = 0x09;
const FIFO_CTRL4: u8 = 0x0A;
const COUNTER_BDR_REG1: u8 = 0x0B;
const INT1_CTRL: u8 = 0x0D;
const CTRL1: u8 = 0x10;
const CTRL2: u8 = 0x11;
const CTRL3: u8 = 0x12;
const CTRL6: u8 = 0x15;
const CTRL8: u8 = 0x17;
const FIFO_STATUS1: u8 = 0x1B;
const ALL_INT_SRC: u8 = 0x1D;
const CTRL1_XL_HG: u8 = 0x4E;
const FUNCTIONS_ENABLE: u8 = 0x50;
const INACTIVITY_DUR: u8 = 0x54;
const TAP_CFG0: u8 = 0x56;
const WAKE_UP_THS: u8 = 0x5B;
const WAKE_UP_DUR: u8 = 0x5C;
const MD1_CFG: u8 = 0x5E;
const FIFO_DATA_OUT_TAG: u8 = 0x78;

/// `init` at 240 Hz (`DataRate::_240hz` = 0x7), ±16 g (`XlFullScale::_16g` = 3), ±4 000 °/s
/// (`GyFullScale::_4000dps` = 5), high-g ±128 g (`HgXlFullScale` 2) at 960 Hz
/// (`HgXlDataRate::_960hz` = 4), then the FIFO with a watermark of 48 words.
fn init_240hz() -> Vec<T> {
    init_at(ADDR, 0x22, 0x08)
}

/// [`init_240hz`] at `a`, with `CTRL1_XL_HG` = `hg` and `COUNTER_BDR_REG1` = `batch`.
fn init_at(a: u8, hg: u8, batch: u8) -> Vec<T> {
    let mut t = vec![
        T::write_read(a, vec![WHO_AM_I], vec![0x73]),
        // ST's sw_reset: low-g off in normal mode (0x7 << 4), gyro off in low-power mode
        // (0x5 << 4), high-g off …
        T::write(a, vec![CTRL1, 0x70]),
        T::write(a, vec![CTRL2, 0x50]),
        T::write(a, vec![CTRL1_XL_HG, 0x00]),
        // … SW_RESET (bit 0) with IF_INC (bit 2) and BDU (bit 6) at their defaults …
        T::write(a, vec![CTRL3, 0x45]),
        // … and SW_RESET read back clear.
        T::write_read(a, vec![CTRL3], vec![0x44]),
        // FS_G = 5 in bits 0–2, bit 3 reserved (reads 1).
        T::write(a, vec![CTRL6, 0x0D]),
        T::write(a, vec![CTRL8, 0x03]),
        // ODR 240 Hz, OP_MODE high-performance (0).
        T::write(a, vec![CTRL1, 0x07]),
        T::write(a, vec![CTRL2, 0x07]),
        // FS_XL_HG = 2 (bits 0–2), ODR_XL_HG = 4 (bits 3–5).
        T::write(a, vec![CTRL1_XL_HG, hg]),
    ];
    t.extend(fifo_at(a, batch));
    t
}

/// FIFO: bypass (0), WTM 48, BDR_XL = BDR_GY = 240 Hz (0x7 each nibble), XL_HG_BATCH_EN
/// (bit 3), continuous (6), INT1_FIFO_TH (bit 3) and INT1_FIFO_OVR (bit 4).
fn fifo_on() -> Vec<T> {
    fifo_at(ADDR, 0x08)
}

fn fifo_at(a: u8, batch: u8) -> Vec<T> {
    vec![
        T::write(a, vec![FIFO_CTRL4, 0x00]),
        T::write(a, vec![FIFO_CTRL1, 48]),
        T::write(a, vec![FIFO_CTRL3, 0x77]),
        T::write(a, vec![COUNTER_BDR_REG1, batch]),
        T::write(a, vec![FIFO_CTRL4, 0x06]),
        T::write(a, vec![INT1_CTRL, 0x18]),
    ]
}

/// The motion wait at 15 Hz (0x3) in low-power mode 1 (0x4 << 4), WU_INACT_THS_W = 2
/// (bits 4–6) with XL_INACT_ODR at its reset 01 (bits 2–3), WK_THS = 3, LIR, INTERRUPTS_ENABLE
/// (bit 7), INT1_WU (bit 5), then ALL_INT_SRC read to clear.
fn enter_wake() -> Vec<T> {
    vec![
        T::write(ADDR, vec![INT1_CTRL, 0x00]),
        T::write(ADDR, vec![FIFO_CTRL4, 0x00]),
        T::write(ADDR, vec![CTRL1_XL_HG, 0x00]),
        T::write(ADDR, vec![CTRL2, 0x00]),
        T::write(ADDR, vec![CTRL1, 0x43]),
        T::write(ADDR, vec![INACTIVITY_DUR, 0x24]),
        T::write(ADDR, vec![WAKE_UP_THS, 0x03]),
        T::write(ADDR, vec![WAKE_UP_DUR, 0x00]),
        T::write(ADDR, vec![TAP_CFG0, 0x01]),
        T::write(ADDR, vec![FUNCTIONS_ENABLE, 0x80]),
        T::write(ADDR, vec![MD1_CFG, 0x20]),
        T::write_read(ADDR, vec![ALL_INT_SRC], vec![0x00]),
    ]
}

fn leave_wake() -> Vec<T> {
    let mut t = vec![
        T::write(ADDR, vec![MD1_CFG, 0x00]),
        T::write(ADDR, vec![FUNCTIONS_ENABLE, 0x00]),
        T::write(ADDR, vec![TAP_CFG0, 0x00]),
        T::write(ADDR, vec![CTRL1, 0x07]),
        T::write(ADDR, vec![CTRL2, 0x07]),
        T::write(ADDR, vec![CTRL1_XL_HG, 0x22]),
    ];
    t.extend(fifo_on());
    t
}

/// A FIFO word's transfer: the tag byte (`TAG_SENSOR` bits 3–7, `TAG_CNT` bits 1–2), then X,
/// Y, Z little-endian.
fn word(tag: u8, cnt: u8, xyz: [i16; 3]) -> T {
    let mut b = vec![(tag << 3) | (cnt << 1)];
    for v in xyz {
        b.extend_from_slice(&v.to_le_bytes());
    }
    T::write_read(ADDR, vec![FIFO_DATA_OUT_TAG], b)
}

fn with(mut a: Vec<T>, b: Vec<T>) -> Vec<T> {
    a.extend(b);
    a
}

#[maybe_async_cfg::maybe(
    idents(asynch(sync = "blocking", async)),
    sync(self = "blocking_cases"),
    async(self = "async_cases")
)]
mod cases {
    use super::*;
    use embedded_hal::i2c::ErrorKind;
    use embedded_hal_mock::eh1::delay::NoopDelay;
    use embedded_hal_mock::eh1::i2c::Mock;
    use gaitclip_lsm6dsv320x::asynch::Lsm6dsv320x;
    use gaitclip_lsm6dsv320x::fifo::{FifoWord, Tag};
    use gaitclip_lsm6dsv320x::mode::Sampling;
    use gaitclip_lsm6dsv320x::{Address, Config, Error, MotionWakeConfig, Odr};

    fn config() -> Config {
        Config::new(Odr::Hz240)
    }

    async fn sampling(rest: Vec<T>) -> (Mock, Lsm6dsv320x<Mock, Sampling>) {
        let bus = Mock::new(&with(init_240hz(), rest));
        let imu = Lsm6dsv320x::new(bus.clone(), Address::Sa0Low)
            .init(&mut NoopDelay, &config())
            .await
            .unwrap();
        (bus, imu)
    }

    pub async fn init_resets_and_configures() {
        let (mut bus, _imu) = sampling(vec![]).await;
        bus.done();
    }

    pub async fn sa0_high_and_no_high_g() {
        // The same program at 0x6B, with the high-g channel off and not batched.
        let mut bus = Mock::new(&init_at(0x6B, 0x00, 0x00));
        let c = Config {
            high_g: None,
            ..config()
        };
        let _imu = Lsm6dsv320x::new(bus.clone(), Address::Sa0High)
            .init(&mut NoopDelay, &c)
            .await
            .unwrap();
        bus.done();
    }

    pub async fn wrong_device_hands_the_driver_back() {
        let mut bus = Mock::new(&[T::write_read(ADDR, vec![WHO_AM_I], vec![0x70])]);
        let e = Lsm6dsv320x::new(bus.clone(), Address::Sa0Low)
            .init(&mut NoopDelay, &config())
            .await
            .unwrap_err();
        assert_eq!(e.error, Error::WrongDevice(0x70));
        e.dev.release();
        bus.done();
    }

    pub async fn a_reset_that_does_not_finish_is_a_verify_error() {
        let t: Vec<T> = init_240hz()
            .into_iter()
            .take(6)
            .map(|x| {
                if x == T::write_read(ADDR, vec![CTRL3], vec![0x44]) {
                    T::write_read(ADDR, vec![CTRL3], vec![0x45])
                } else {
                    x
                }
            })
            .collect();
        let mut bus = Mock::new(&t);
        let e = Lsm6dsv320x::new(bus.clone(), Address::Sa0Low)
            .init(&mut NoopDelay, &config())
            .await
            .unwrap_err();
        assert_eq!(e.error, Error::Verify(CTRL3, 0x44, 0x45));
        bus.done();
    }

    pub async fn a_bus_error_hands_the_driver_back_to_retry() {
        let mut t = vec![
            T::write_read(ADDR, vec![WHO_AM_I], vec![0x73]),
            T::write(ADDR, vec![CTRL1, 0x70]).with_error(ErrorKind::Other),
        ];
        t.extend(init_240hz());
        let mut bus = Mock::new(&t);
        let e = Lsm6dsv320x::new(bus.clone(), Address::Sa0Low)
            .init(&mut NoopDelay, &config())
            .await
            .unwrap_err();
        assert_eq!(e.error, Error::Bus(ErrorKind::Other));
        let _imu = e.dev.init(&mut NoopDelay, &config()).await.unwrap();
        bus.done();
    }

    pub async fn fifo_words_in_order_with_their_slots() {
        let (mut bus, mut imu) = sampling(vec![
            // DIFF_FIFO = 3, watermark flag (bit 7 of FIFO_STATUS2).
            T::write_read(ADDR, vec![FIFO_STATUS1], vec![0x03, 0x80]),
            word(0x1D, 1, [300, -20, 7000]),
            word(0x02, 1, [-1, 2048, 32767]),
            word(0x01, 1, [100, -100, -32768]),
        ])
        .await;
        let mut out = [FifoWord {
            tag: Tag::Other(0),
            slot: 0,
            data: [0; 3],
        }; 8];
        assert_eq!(imu.read_fifo(&mut out).await, Ok(3));
        assert_eq!(out[0].tag, Tag::HighG);
        assert_eq!(out[0].data, [300, -20, 7000]);
        assert_eq!(out[1].tag, Tag::Accel);
        assert_eq!(out[1].data, [-1, 2048, 32767]);
        assert_eq!(out[2].tag, Tag::Gyro);
        assert_eq!(out[2].data, [100, -100, -32768]);
        assert!(out[..3].iter().all(|w| w.slot == 1));
        bus.done();
    }

    pub async fn fifo_reads_no_more_than_the_buffer_holds_and_counts_bit_8() {
        // DIFF_FIFO = 0x100 + 2 = 258 words waiting; a buffer of 2 takes 2.
        let (mut bus, mut imu) = sampling(vec![
            T::write_read(ADDR, vec![FIFO_STATUS1], vec![0x02, 0x01]),
            word(0x02, 3, [1, 2, 3]),
            word(0x01, 3, [4, 5, 6]),
        ])
        .await;
        let mut out = [FifoWord {
            tag: Tag::Other(0),
            slot: 0,
            data: [0; 3],
        }; 2];
        assert_eq!(imu.read_fifo(&mut out).await, Ok(2));
        assert_eq!(out[1].data, [4, 5, 6]);
        assert_eq!(out[1].slot, 3);
        bus.done();
    }

    pub async fn an_overrun_empties_the_fifo_and_is_an_error() {
        let (mut bus, mut imu) = sampling(vec![
            // FIFO_OVR_IA (bit 6) with the FIFO full (bit 5) and 0x1FF words.
            T::write_read(ADDR, vec![FIFO_STATUS1], vec![0xFF, 0x61]),
            T::write(ADDR, vec![FIFO_CTRL4, 0x00]),
            T::write(ADDR, vec![FIFO_CTRL4, 0x06]),
            // Latched overrun alone (bit 3) is an overrun too.
            T::write_read(ADDR, vec![FIFO_STATUS1], vec![0x00, 0x08]),
            T::write(ADDR, vec![FIFO_CTRL4, 0x00]),
            T::write(ADDR, vec![FIFO_CTRL4, 0x06]),
        ])
        .await;
        let mut out = [FifoWord {
            tag: Tag::Other(0),
            slot: 0,
            data: [0; 3],
        }; 4];
        assert_eq!(imu.read_fifo(&mut out).await, Err(Error::FifoOverflow));
        assert_eq!(imu.read_fifo(&mut out).await, Err(Error::FifoOverflow));
        bus.done();
    }

    pub async fn a_word_that_fails_keeps_the_words_read_before_it() {
        let (mut bus, mut imu) = sampling(vec![
            T::write_read(ADDR, vec![FIFO_STATUS1], vec![0x03, 0x00]),
            word(0x02, 2, [1, 2, 3]),
            word(0x01, 2, [4, 5, 6]),
            T::write_read(ADDR, vec![FIFO_DATA_OUT_TAG], vec![0; 7]).with_error(ErrorKind::Other),
        ])
        .await;
        let mut out = [FifoWord {
            tag: Tag::Other(0),
            slot: 0,
            data: [0; 3],
        }; 8];
        let (n, result) = imu.read_fifo_partial(&mut out).await;
        assert_eq!((n, result), (2, Err(Error::Bus(ErrorKind::Other))));
        assert_eq!((out[0].data, out[1].data), ([1, 2, 3], [4, 5, 6]));
        bus.done();
    }

    pub async fn motion_wake_in_and_out() {
        let mut rest = enter_wake();
        // Not yet, then the wake-up (WU_IA, bit 1, with the axis bits).
        rest.push(T::write_read(ADDR, vec![ALL_INT_SRC], vec![0x00]));
        rest.push(T::write_read(ADDR, vec![ALL_INT_SRC], vec![0x02]));
        rest.extend(leave_wake());
        let (mut bus, imu) = sampling(rest).await;
        let mut imu = imu
            .enter_motion_wake(&mut NoopDelay, &MotionWakeConfig::DEFAULT)
            .await
            .unwrap();
        assert_eq!(imu.read_wake_source().await, Ok(false));
        assert_eq!(imu.read_wake_source().await, Ok(true));
        let _imu = imu
            .leave_motion_wake(&mut NoopDelay, &config())
            .await
            .unwrap();
        bus.done();
    }
}

macro_rules! both {
    ($($name:ident),* $(,)?) => {
        mod blocking {
            $(#[test]
            fn $name() {
                super::blocking_cases::$name();
            })*
        }
        mod asynch {
            $(#[test]
            fn $name() {
                futures_executor::block_on(super::async_cases::$name());
            })*
        }
    };
}

both!(
    init_resets_and_configures,
    sa0_high_and_no_high_g,
    wrong_device_hands_the_driver_back,
    a_reset_that_does_not_finish_is_a_verify_error,
    a_bus_error_hands_the_driver_back_to_retry,
    fifo_words_in_order_with_their_slots,
    fifo_reads_no_more_than_the_buffer_holds_and_counts_bit_8,
    an_overrun_empties_the_fifo_and_is_an_error,
    a_word_that_fails_keeps_the_words_read_before_it,
    motion_wake_in_and_out,
);
