//! The runner against a mocked bus, every transaction spelt out, on the blocking runner and,
//! from the same source, the async one.

use embedded_hal_mock::eh1::i2c::Transaction as T;
use gaitclip_regbus::{Identity, ProgramError, Step};

const ADDR: u8 = 0x42;
const ID: Identity = Identity {
    reg: 0x0F,
    value: 0x73,
};

const PROGRAM: [Step; 5] = [
    Step::Identify,
    Step::Write {
        reg: 0x12,
        value: 0x45,
    },
    Step::WaitMs(1),
    Step::Check {
        reg: 0x12,
        value: 0x44,
    },
    Step::Read { reg: 0x1D },
];

fn program_on_the_bus(ctrl3_after: u8) -> Vec<T> {
    vec![
        T::write_read(ADDR, vec![0x0F], vec![0x73]),
        T::write(ADDR, vec![0x12, 0x45]),
        T::write_read(ADDR, vec![0x12], vec![ctrl3_after]),
        T::write_read(ADDR, vec![0x1D], vec![0x02]),
    ]
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
    use gaitclip_regbus::asynch::RegisterBus;

    pub async fn a_program_runs_step_by_step() {
        let mut mock = Mock::new(&program_on_the_bus(0x44));
        let mut bus = RegisterBus::new(mock.clone(), ADDR);
        assert_eq!(bus.run(&PROGRAM, &mut NoopDelay, ID).await, Ok(()));
        bus.release();
        mock.done();
    }

    pub async fn a_register_that_does_not_read_back_ends_it() {
        let mut t = program_on_the_bus(0x45);
        t.pop(); // the read after the check never happens
        let mut mock = Mock::new(&t);
        let mut bus = RegisterBus::new(mock.clone(), ADDR);
        assert_eq!(
            bus.run(&PROGRAM, &mut NoopDelay, ID).await,
            Err(ProgramError::Verify(0x12, 0x44, 0x45))
        );
        mock.done();
    }

    pub async fn another_part_ends_it_at_once() {
        let mut mock = Mock::new(&[T::write_read(ADDR, vec![0x0F], vec![0x68])]);
        let mut bus = RegisterBus::new(mock.clone(), ADDR);
        assert_eq!(
            bus.run(&PROGRAM, &mut NoopDelay, ID).await,
            Err(ProgramError::WrongDevice(0x68))
        );
        mock.done();
    }

    pub async fn a_bus_error_ends_it() {
        let mut mock = Mock::new(&[
            T::write_read(ADDR, vec![0x0F], vec![0x73]),
            T::write(ADDR, vec![0x12, 0x45]).with_error(ErrorKind::Other),
        ]);
        let mut bus = RegisterBus::new(mock.clone(), ADDR);
        assert_eq!(
            bus.run(&PROGRAM, &mut NoopDelay, ID).await,
            Err(ProgramError::Bus(ErrorKind::Other))
        );
        mock.done();
    }

    pub async fn reads_are_one_transfer_from_the_register() {
        let mut mock = Mock::new(&[T::write_read(ADDR, vec![0x78], vec![1, 2, 3, 4, 5, 6, 7])]);
        let mut bus = RegisterBus::new(mock.clone(), ADDR);
        let mut buf = [0u8; 7];
        bus.read(0x78, &mut buf).await.unwrap();
        assert_eq!(buf, [1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(bus.address(), ADDR);
        mock.done();
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
    a_program_runs_step_by_step,
    a_register_that_does_not_read_back_ends_it,
    another_part_ends_it_at_once,
    a_bus_error_ends_it,
    reads_are_one_transfer_from_the_register,
);
