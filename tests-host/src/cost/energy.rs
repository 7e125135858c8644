//! The energy budget of the boards with a real sensor: average current while walking and
//! while still, and what it makes of a coin cell and a small LiPo.
//!
//! Measured where this machine can measure, modelled where it cannot:
//!
//! * **Measured**: the instructions the pipeline executes per sample of real walking, strides
//!   included (`gaitclip cost` counts them in QEMU with the `qemu-insn-count` plugin on the
//!   benchmark firmware: the M4 build stands for the nRF52840, the M0 build for the RP2040).
//! * **Modelled from the firmware**: the I²C bus time of a FIFO burst (the driver's
//!   transactions, bit by bit at 400 kHz, [`i2c_bits_per_burst`]), during which the core
//!   waits in the blocking driver; the Bluetooth build's advertising air time (its
//!   advertising data, the Core specification's packet layout).
//! * **From datasheets**: every current ([`Cited`]), with its document and section. No
//!   board was on a meter: no figure here is a measurement of current.
//!
//! Cycles are taken as equal to instructions (CPI 1): flash wait states and cache misses make
//! it more, and [`savings`] shows what doubling them would change.

use std::fmt::Write as _;

use gaitclip_board::live_settings::mpu6050::{FIFO_BATCH, RATE_HZ};
use gaitclip_board::sleep::SLEEP;
use gaitclip_mpu6050::WakeRate;

use crate::eval::markdown::{Column, Table};

/// A current from a datasheet, µA.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cited {
    /// Typical current, µA.
    pub ua: f64,
    /// Document, section and the row or conditions it is taken from.
    pub source: &'static str,
}

/// MPU6050 with gyroscope and accelerometer on (DMP off).
pub const MPU6050_SAMPLING: Cited = Cited {
    ua: 3800.0,
    source: "MPU-6000/6050 Product Specification PS-MPU-6000A-00 rev 3.4, §6.3: normal operating current, gyroscope + accelerometer, DMP disabled",
};

/// MPU6050 accelerometer-only cycle mode at `rate` (the driver's [`WakeRate::supply_ua`]).
pub fn mpu6050_cycle(rate: WakeRate) -> Cited {
    Cited {
        ua: f64::from(rate.supply_ua()),
        source:
            "PS-MPU-6000A-00 rev 3.4, §6.3: accelerometer low-power mode current at the wake rate",
    }
}

/// nRF52840 CPU running from flash at 64 MHz, DC/DC on (both nRF builds enable it).
pub const NRF_CPU: Cited = Cited {
    ua: 3300.0,
    source: "nRF52840 Product Specification v1.11, §5.2 current consumption, ICPU0: CoreMark from flash, 64 MHz, HFXO, cache on, DC/DC, 3 V (6.3 mA with the LDO)",
};
/// nRF52840 System ON, CPU sleeping, all RAM kept, woken by an event.
pub const NRF_IDLE: Cited = Cited {
    ua: 2.35,
    source:
        "nRF52840 PS v1.11, §5.2, ION_RAMON_EVENT: System ON, full RAM retention, wake on any event",
};
/// nRF52840 System ON with the RTC running (the sleep clock), all RAM kept.
pub const NRF_SLEEP: Cited = Cited {
    ua: 3.16,
    source: "nRF52840 PS v1.11, §5.2, ION_RAMON_RTC: System ON, full RAM retention, wake on RTC",
};
/// nRF52840 radio transmitting at 0 dBm, 1 Mb/s, DC/DC.
pub const NRF_TX: Cited = Cited {
    ua: 4800.0,
    source: "nRF52840 PS v1.11, key features: TX at 0 dBm, DC/DC, 3 V",
};
/// nRF52840 radio receiving at 1 Mb/s, DC/DC.
pub const NRF_RX: Cited = Cited {
    ua: 4600.0,
    source: "nRF52840 PS v1.11, key features: RX at 1 Mb/s, DC/DC, 3 V",
};
/// The radio's ramp-up before each transmission or reception, µs.
pub const NRF_RAMP_UP_US: f64 = 140.0;

/// RP2040 running both cores at 48 MHz with VGA, I²S and SD card busy: the datasheet's only
/// figure for a running chip, used per MHz.
pub const RP2040_RUNNING_48MHZ: Cited = Cited {
    ua: 10_900.0,
    source: "RP2040 Datasheet, §5.7.2, Table 637: 'Popcorn' use case, typical average DVDD current, clk_sys 48 MHz",
};
/// RP2040 in BOOTSEL mode with the USB idle: a core waiting in a loop at 48 MHz.
pub const RP2040_IDLE_48MHZ: Cited = Cited {
    ua: 9000.0,
    source: "RP2040 Datasheet, §5.7.2, Table 637: BOOTSEL mode, USB idle, typical average DVDD current (48 MHz)",
};
/// RP2040 in DORMANT: every clock stopped, woken by a GPIO.
pub const RP2040_DORMANT: Cited = Cited {
    ua: 180.0,
    source: "RP2040 Datasheet, §5.7.2, Table 637: Dormant, typical average DVDD current",
};
/// RP2040 in SLEEP: the processors' clocks stopped, the others selectable.
pub const RP2040_SLEEP: Cited = Cited {
    ua: 390.0,
    source: "RP2040 Datasheet, §5.7.2, Table 637: Sleep, typical average DVDD current",
};

/// The Pico build's system clock, MHz.
pub const RP2040_CLOCK_MHZ: f64 = 125.0;
/// The nRF52840's core clock, MHz.
pub const NRF_CLOCK_MHZ: f64 = 64.0;
/// The I²C clock, Hz (the MPU6050's fast mode).
pub const I2C_HZ: f64 = 400_000.0;

/// Batteries: name and capacity, mAh.
pub const BATTERIES: [(&str, f64); 2] = [("CR2032 (225 mAh)", 225.0), ("LiPo 100 mAh", 100.0)];

/// Bits on the bus for one FIFO burst of `batch` samples, as the driver reads it
/// (`Mpu6050::read_fifo`): `INT_STATUS` (write the register, read one byte), `FIFO_COUNT`
/// (two bytes), then one 14-byte read of `FIFO_R_W` per sample. Each byte is 9 clocks (8 and
/// the acknowledge); a START, repeated START and STOP about one clock each.
pub fn i2c_bits_per_burst(batch: u32) -> u32 {
    // address + register, repeated start, address + `n` bytes, stop.
    let write_read = |n: u32| 3 + 9 * (1 + 1 + 1 + n);
    write_read(1) + write_read(2) + batch * write_read(14)
}

/// The average currents of one board, µA, by part.
#[derive(Clone, Debug, PartialEq)]
pub struct Budget {
    /// The board as the table names it.
    pub board: &'static str,
    /// While walking: (part, µA) in table order.
    pub walking: Vec<(&'static str, f64)>,
    /// While still (asleep): (part, µA).
    pub still: Vec<(&'static str, f64)>,
    /// What the figures assume that is not a datasheet row.
    pub notes: Vec<String>,
}

impl Budget {
    /// Total while walking, µA.
    pub fn walking_ua(&self) -> f64 {
        self.walking.iter().map(|p| p.1).sum()
    }
    /// Total while still, µA.
    pub fn still_ua(&self) -> f64 {
        self.still.iter().map(|p| p.1).sum()
    }
    /// Hours of walking on `mah`.
    pub fn walking_hours(&self, mah: f64) -> f64 {
        mah * 1000.0 / self.walking_ua()
    }
    /// Days standing still on `mah`.
    pub fn standby_days(&self, mah: f64) -> f64 {
        mah * 1000.0 / self.still_ua() / 24.0
    }
    /// Days of use at `walk_h` hours of walking a day, still the rest of it, on `mah`.
    pub fn days_of_use(&self, mah: f64, walk_h: f64) -> f64 {
        let per_day_uah = self.walking_ua() * walk_h + self.still_ua() * (24.0 - walk_h);
        mah * 1000.0 / per_day_uah
    }
}

/// What the MCU does per second of walking: compute and I²C waiting, in seconds per second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Duty {
    /// Executing the pipeline: instructions per second over the clock.
    pub compute: f64,
    /// Waiting in the blocking driver while the bus transfers.
    pub i2c: f64,
}

impl Duty {
    /// The duty at `insn_per_sample` instructions per sample (strides included), on a core
    /// of `mhz`, with `cpi` cycles per instruction.
    pub fn of(insn_per_sample: f64, mhz: f64, cpi: f64) -> Duty {
        let rate = f64::from(RATE_HZ);
        let bursts = rate / f64::from(FIFO_BATCH);
        Duty {
            compute: insn_per_sample * rate * cpi / (mhz * 1e6),
            i2c: bursts * f64::from(i2c_bits_per_burst(u32::from(FIFO_BATCH))) / I2C_HZ,
        }
    }
}

/// The nRF52840-DK build.
pub fn nrf52840(insn_per_sample: f64, cpi: f64) -> Budget {
    let d = Duty::of(insn_per_sample, NRF_CLOCK_MHZ, cpi);
    let busy = d.compute + d.i2c;
    Budget {
        board: "nRF52840-DK (`boards/nrf52840-dk`)",
        walking: vec![
            ("MPU6050 sampling", MPU6050_SAMPLING.ua),
            ("CPU: pipeline", d.compute * NRF_CPU.ua),
            ("CPU: waiting on I²C", d.i2c * NRF_CPU.ua),
            ("CPU sleeping between", (1.0 - busy) * NRF_IDLE.ua),
        ],
        still: vec![
            ("MPU6050 cycle mode", mpu6050_cycle(SLEEP.wake.rate).ua),
            ("nRF52840 System ON, RTC", NRF_SLEEP.ua),
        ],
        notes: vec![
            format!(
                "CPU busy {:.2} % computing and {:.2} % waiting for I²C (a FIFO burst of {FIFO_BATCH} samples is {} bits at 400 kHz, {:.2} ms every {} ms)",
                d.compute * 100.0,
                d.i2c * 100.0,
                i2c_bits_per_burst(u32::from(FIFO_BATCH)),
                f64::from(i2c_bits_per_burst(u32::from(FIFO_BATCH))) / I2C_HZ * 1e3,
                1000 * u32::from(FIFO_BATCH) / u32::from(RATE_HZ)
            ),
            "not included: the crystal oscillator and TWIM/UARTE peripherals while awake (no figure in the sources used), the UART lines".into(),
        ],
    }
}

/// An nRF52840 budget with the I²C wait at the idle current: the core sleeps while the
/// TWIM's EasyDMA transfers instead of spinning in a blocking driver.
fn awaiting_transfers(b: &mut Budget, insn_per_sample: f64, cpi: f64) {
    let d = Duty::of(insn_per_sample, NRF_CLOCK_MHZ, cpi);
    b.walking[2] = (
        "CPU idle while the TWIM transfers (awaited)",
        d.i2c * NRF_IDLE.ua,
    );
}

/// Air time of one advertising event, µs: on each of the three channels the radio ramps up
/// and sends the ADV_IND (preamble 1, access address 4, header 2, advertiser address 6, the
/// data, CRC 3 bytes at 1 Mb/s: 8 µs a byte), then ramps up and listens for T_IFS (150 µs)
/// for a scan or connection request (Bluetooth Core 5.4, Vol 6, Part B, §2.1 and §4.4.2).
pub fn advertising_event_us(adv_data_len: usize) -> (f64, f64) {
    let packet_us = (1 + 4 + 2 + 6 + adv_data_len + 3) as f64 * 8.0;
    let tx = 3.0 * (NRF_RAMP_UP_US + packet_us);
    let rx = 3.0 * (NRF_RAMP_UP_US + 150.0);
    (tx, rx)
}

/// The Bluetooth build: the DK build's figures and advertising (no central connected) at
/// 152 ms while awake, 2000 ms asleep.
pub fn nrf52840_ble(insn_per_sample: f64, cpi: f64) -> Budget {
    let mut b = nrf52840(insn_per_sample, cpi);
    b.board = "nRF52840-DK + Bluetooth (`boards/nrf52840-ble`), advertising";
    // This build awaits each transfer (`imu_sampler::asynch` over the TWIM's EasyDMA): the
    // executor has nothing to run and the core idles in `wfe` while the bytes move.
    awaiting_transfers(&mut b, insn_per_sample, cpi);
    let mut adv = [0u8; 31];
    let len = gaitclip_board::rsc_gatt::advertising_data(&mut adv).unwrap_or(31);
    let (tx, rx) = advertising_event_us(len);
    let event_ua = (tx * NRF_TX.ua + rx * NRF_RX.ua) / 1e6;
    let awake = gaitclip_board::rsc_gatt::ADVERTISING_INTERVAL_MS as f64 / 1000.0;
    let asleep = gaitclip_board::rsc_gatt::SLEEPING_ADVERTISING_INTERVAL_MS as f64 / 1000.0;
    b.walking.push(("radio: advertising", event_ua / awake));
    b.still
        .push(("radio: advertising slowly", event_ua / asleep));
    b.notes.push(format!(
        "advertising: {len} bytes of data, {tx:.0} µs of TX and {rx:.0} µs of RX per event (ramp-up {NRF_RAMP_UP_US} µs each) every {} ms awake, {} ms asleep; the controller's CPU time per event is not included, and connected, the central's connection interval decides",
        gaitclip_board::rsc_gatt::ADVERTISING_INTERVAL_MS,
        gaitclip_board::rsc_gatt::SLEEPING_ADVERTISING_INTERVAL_MS
    ));
    b
}

/// The Pico build as it is: its clocks run while the core waits in `wfi`, asleep or not.
pub fn rp2040(insn_per_sample: f64, cpi: f64) -> Budget {
    let d = Duty::of(insn_per_sample, RP2040_CLOCK_MHZ, cpi);
    let per_mhz_running = RP2040_RUNNING_48MHZ.ua / 48.0;
    let per_mhz_waiting = RP2040_IDLE_48MHZ.ua / 48.0;
    let running = per_mhz_running * RP2040_CLOCK_MHZ;
    let waiting = per_mhz_waiting * RP2040_CLOCK_MHZ;
    let busy = d.compute + d.i2c;
    Budget {
        board: "Raspberry Pi Pico (`boards/rp-pico`)",
        walking: vec![
            ("MPU6050 sampling", MPU6050_SAMPLING.ua),
            ("RP2040: pipeline", d.compute * running),
            ("RP2040: waiting on I²C", d.i2c * running),
            ("RP2040 in `wfi`, clocks running", (1.0 - busy) * waiting),
        ],
        still: vec![
            ("MPU6050 cycle mode", mpu6050_cycle(SLEEP.wake.rate).ua),
            ("RP2040 in `wfi`, clocks running", waiting),
        ],
        notes: vec![
            format!(
                "CPU busy {:.2} % computing and {:.2} % waiting for I²C at {RP2040_CLOCK_MHZ} MHz; running current scaled from Table 637's 48 MHz rows per MHz ({per_mhz_running:.0} µA/MHz running, {per_mhz_waiting:.0} µA/MHz waiting): a model, the datasheet has no row for a core in `wfi` at 125 MHz",
                d.compute * 100.0,
                d.i2c * 100.0
            ),
            format!(
                "DORMANT (not built) would make the still current {:.0} µA: the RP2040 alone draws {:.0} µA there, more than the 30 µA target",
                mpu6050_cycle(SLEEP.wake.rate).ua + RP2040_DORMANT.ua,
                RP2040_DORMANT.ua
            ),
        ],
    }
}

/// One MCU-side saving and what it changes in days of use at 1 h of walking a day.
#[derive(Clone, Debug, PartialEq)]
pub struct Saving {
    /// What is changed.
    pub what: String,
    /// Days of use before and after (CR2032), and the change in %.
    pub days: (f64, f64, f64),
}

/// What the MCU-side changes would give on the nRF52840, against the budget as built.
pub fn savings(insn_per_sample: f64) -> Vec<Saving> {
    let cr2032 = BATTERIES[0].1;
    let base = nrf52840(insn_per_sample, 1.0).days_of_use(cr2032, 1.0);
    let of = |what: String, b: &Budget| {
        let d = b.days_of_use(cr2032, 1.0);
        Saving {
            what,
            days: (base, d, (d / base - 1.0) * 100.0),
        }
    };
    let mut out = Vec::new();
    out.push(of(
        "sample path in half the instructions".into(),
        &nrf52840(insn_per_sample / 2.0, 1.0),
    ));
    out.push(of(
        "twice the cycles per instruction (wait states)".into(),
        &nrf52840(insn_per_sample, 2.0),
    ));
    let mut dma = nrf52840(insn_per_sample, 1.0);
    awaiting_transfers(&mut dma, insn_per_sample, 1.0);
    out.push(of(
        "the core asleep while the TWIM's DMA transfers (the I²C wait at idle current; done on the Bluetooth build, whose sampler awaits it)".into(),
        &dma,
    ));
    let mut ldo = nrf52840(insn_per_sample, 1.0);
    let ratio = 6300.0 / NRF_CPU.ua;
    ldo.walking[1].1 *= ratio;
    ldo.walking[2].1 *= ratio;
    let ldo_days = ldo.days_of_use(cr2032, 1.0);
    out.push(Saving {
        what: "DC/DC converter on instead of the LDO (done: both nRF builds enable it)".into(),
        days: (ldo_days, base, (base / ldo_days - 1.0) * 100.0),
    });
    out
}

/// The budget tables in Markdown, for docs/energy.md: the nRF52840 builds at `m4_insn` and the
/// Pico at `m0_insn` instructions per sample of walking (strides included).
/// How much a sensor may draw for `hours_of_use` on `mah` at one hour of walking a day, on
/// `board` with its own sensor's rows (`sensor_walking`, `sensor_still`) taken out: the
/// largest walking current, µA, with the sensor's still current at `sensor_still_ua`
/// (negative: the rest of the board alone spends more than the battery gives).
pub fn sensor_allowance_ua(
    board: &Budget,
    sensor_rows: (&str, &str),
    mah: f64,
    hours_of_use: f64,
    sensor_still_ua: f64,
) -> f64 {
    let without = |parts: &[(&str, f64)], name: &str| -> f64 {
        parts.iter().filter(|p| p.0 != name).map(|p| p.1).sum()
    };
    let other_walking = without(&board.walking, sensor_rows.0);
    let other_still = without(&board.still, sensor_rows.1);
    // One hour of walking a day: `hours_of_use` days, each 1 h walking and 23 h still.
    let per_day_uah = mah * 1000.0 / hours_of_use;
    per_day_uah - other_walking - 23.0 * (other_still + sensor_still_ua)
}

/// Hours of use (at one hour of walking a day) on `mah` of the sensor alone, walking at
/// `walking_ua` and still at `still_ua`: the physical floor no MCU work can lower.
pub fn sensor_floor_hours(mah: f64, walking_ua: f64, still_ua: f64) -> f64 {
    mah * 1000.0 / (walking_ua + 23.0 * still_ua)
}

/// The hours of use a second sensor is judged by (issue 47), and a commercial foot pod's.
pub const HOURS_OF_USE_TARGETS: [f64; 2] = [250.0, 400.0];
/// Still currents of a sensor's wake-up mode the allowance is given for, µA.
pub const SENSOR_STILL_UA: [f64; 3] = [5.0, 10.0, 20.0];

fn allowance_section(o: &mut String, ble: &Budget) {
    let (mah_name, mah) = BATTERIES[0];
    let cycle = mpu6050_cycle(SLEEP.wake.rate).ua;
    let _ = writeln!(
        o,
        "\nThe sensor's share on the Bluetooth build, {mah_name}, one hour of walking a day. The floor: the MPU6050 alone (MCU and radio drawing nothing) gives {:.0} hours of use ({:.0} µA walking, {cycle} µA still). What any sensor may draw for a number of hours of use, the rest of the board as above (walking {:.1} µA, still {:.1} µA without the sensor):\n",
        sensor_floor_hours(mah, MPU6050_SAMPLING.ua, cycle),
        MPU6050_SAMPLING.ua,
        ble.walking_ua() - MPU6050_SAMPLING.ua,
        ble.still_ua() - cycle,
    );
    let mut t = Table::new(
        std::iter::once(Column::from("hours of use"))
            .chain(
                SENSOR_STILL_UA
                    .iter()
                    .map(|s| Column::right(format!("sensor walking µA, still at {s} µA"))),
            )
            .collect::<Vec<_>>(),
    );
    for h in HOURS_OF_USE_TARGETS {
        t.row(
            std::iter::once(format!("{h:.0}")).chain(SENSOR_STILL_UA.iter().map(|&s| {
                let ua =
                    sensor_allowance_ua(ble, ("MPU6050 sampling", "MPU6050 cycle mode"), mah, h, s);
                if ua >= 0.0 {
                    format!("{ua:.0}")
                } else {
                    format!("none (the rest is {:.0} over)", -ua)
                }
            })),
        );
    }
    o.push_str(&t.render());
}

pub fn report(m4_insn: f64, m0_insn: f64) -> String {
    let boards = [
        nrf52840(m4_insn, 1.0),
        nrf52840_ble(m4_insn, 1.0),
        rp2040(m0_insn, 1.0),
    ];
    let mut o = String::new();
    let _ = writeln!(
        o,
        "Average current by part, µA, at 3 V; instructions per sample measured ({m4_insn:.0} on the M4, {m0_insn:.0} on the M0, strides included), currents from the datasheets cited below, cycles = instructions.\n"
    );
    for b in &boards {
        let _ = writeln!(o, "**{}**\n", b.board);
        let mut parts = Table::new([
            Column::from("part"),
            Column::right("walking µA"),
            Column::right("still µA"),
        ]);
        let mut names: Vec<&str> = b.walking.iter().map(|p| p.0).collect();
        for p in &b.still {
            if !names.contains(&p.0) {
                names.push(p.0);
            }
        }
        for n in names {
            let cell = |parts: &[(&str, f64)]| {
                parts
                    .iter()
                    .find(|p| p.0 == n)
                    .map_or(String::new(), |p| format!("{:.1}", p.1))
            };
            parts.row([n.to_string(), cell(&b.walking), cell(&b.still)]);
        }
        let still_ok = if b.still_ua() <= 30.0 {
            "≤ 30 µA: met"
        } else {
            "**over the 30 µA target**"
        };
        parts.row([
            "**total**".to_string(),
            format!("**{:.0}**", b.walking_ua()),
            format!("**{:.1}** ({still_ok})", b.still_ua()),
        ]);
        let _ = writeln!(o, "{}", parts.render());
        for n in &b.notes {
            let _ = writeln!(o, "- {n}");
        }
        let _ = writeln!(o);
    }
    let mut life = Table::new([
        Column::from("board"),
        Column::from("battery"),
        Column::right("hours walking"),
        Column::right("days still"),
        Column::right("days of use, 1 h walking a day"),
    ]);
    for b in &boards {
        for (name, mah) in BATTERIES {
            life.row([
                b.board.to_string(),
                name.to_string(),
                format!("{:.0}", b.walking_hours(mah)),
                format!("{:.1}", b.standby_days(mah)),
                format!("{:.1}", b.days_of_use(mah, 1.0)),
            ]);
        }
    }
    o.push_str(&life.render());
    allowance_section(&mut o, &boards[1]);
    let _ = writeln!(
        o,
        "\nA CR2032's 225 mAh is rated at a light drain; at the 4 mA of walking its usable capacity is lower (not modelled).\n"
    );
    let _ = writeln!(
        o,
        "What MCU-side changes give on the nRF52840 (days of use on a CR2032 at 1 h of walking a day):\n"
    );
    let mut changes = Table::new([
        Column::from("change"),
        Column::right("days before"),
        Column::right("days after"),
        Column::right("change"),
    ]);
    for s in savings(m4_insn) {
        changes.row([
            s.what.clone(),
            format!("{:.1}", s.days.0),
            format!("{:.1}", s.days.1),
            format!("{:+.1} %", s.days.2),
        ]);
    }
    o.push_str(&changes.render());
    let _ = writeln!(o, "\nSources:\n");
    let mut cited = vec![
        MPU6050_SAMPLING,
        mpu6050_cycle(SLEEP.wake.rate),
        NRF_CPU,
        NRF_IDLE,
        NRF_SLEEP,
        NRF_TX,
        NRF_RX,
        RP2040_RUNNING_48MHZ,
        RP2040_IDLE_48MHZ,
        RP2040_SLEEP,
        RP2040_DORMANT,
    ];
    cited.dedup_by(|a, b| a.source == b.source);
    for c in cited {
        let _ = writeln!(o, "- {} µA: {}", c.ua, c.source);
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sensor_allowance_gives_back_the_hours_it_was_asked_for() {
        let ble = nrf52840_ble(9600.0, 1.0);
        let rows = ("MPU6050 sampling", "MPU6050 cycle mode");
        // Put a sensor drawing exactly the allowance in the MPU6050's place: the budget then
        // lasts the hours asked for.
        for hours in HOURS_OF_USE_TARGETS {
            let still = 10.0;
            let walking = sensor_allowance_ua(&ble, rows, 225.0, hours, still);
            let mut b = ble.clone();
            b.walking[0] = ("sensor", walking);
            let cycle = b.still.iter().position(|p| p.0 == rows.1).unwrap();
            b.still[cycle] = ("sensor", still);
            assert!((b.days_of_use(225.0, 1.0) - hours).abs() < 1e-9, "{hours}");
        }
        // The MPU6050's own floor: 225 mAh over 3.8 mA for an hour and 20 µA for 23.
        let floor = sensor_floor_hours(225.0, 3800.0, 20.0);
        assert!((floor - 225_000.0 / (3800.0 + 460.0)).abs() < 1e-9);
    }

    #[test]
    fn a_fifo_burst_of_eight_is_1335_bits() {
        // 3 + 9·4, 3 + 9·5, 8 · (3 + 9·17).
        assert_eq!(i2c_bits_per_burst(8), 39 + 48 + 8 * 156);
        assert_eq!(i2c_bits_per_burst(8), 1335);
    }

    #[test]
    fn the_nrf_still_current_is_the_sensor_and_system_on() {
        let b = nrf52840(8000.0, 1.0);
        assert!((b.still_ua() - 23.16).abs() < 1e-9);
        // 200 Hz × 8000 instructions at 64 MHz: 2.5 % of 3.3 mA.
        assert!((b.walking[1].1 - 0.025 * 3300.0).abs() < 1e-6);
        // 25 bursts a second of 1335 bits at 400 kHz: 8.34 %.
        assert!((b.walking[2].1 - 25.0 * 1335.0 / 400_000.0 * 3300.0).abs() < 1e-6);
        // One hour of walking a day on 225 mAh.
        let per_day = b.walking_ua() + 23.0 * b.still_ua();
        assert!((b.days_of_use(225.0, 1.0) - 225_000.0 / per_day).abs() < 1e-9);
    }

    #[test]
    fn advertising_air_time() {
        // 31 bytes of data: 47 bytes on air, 376 µs, plus 140 µs ramp-up, on three channels.
        let (tx, rx) = advertising_event_us(31);
        assert_eq!(tx, 3.0 * (140.0 + 376.0));
        assert_eq!(rx, 3.0 * 290.0);
    }
}
