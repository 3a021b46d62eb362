//! The rules every board map keeps, checked for every board of the list.

use super::*;
use crate::chip::pins::{Output, OutputTimer, Pin};

/// Every pin a map names, with what it is for.
fn all_pins(board: &BoardMap) -> Vec<(Pin, &'static str)> {
    let mut pins = vec![
        (board.link_tx, "link tx"),
        (board.link_rx, "link rx"),
        (board.sbus_rx, "sbus"),
        (board.log_tx, "log"),
        (board.imu.sck, "imu sck"),
        (board.imu.miso, "imu miso"),
        (board.imu.mosi, "imu mosi"),
        (board.imu.cs, "imu cs"),
        (board.imu.int, "imu int"),
        (board.swd[0], "swdio"),
        (board.swd[1], "swclk"),
        (board.esc.pin, "esc"),
    ];
    pins.extend(board.led.map(|led| (led.pin, "led")));
    pins.extend(board.servos.iter().map(|servo| (servo.pin, "servo")));
    pins
}

#[test]
fn the_board_list_names_distinct_boards_and_the_selected_one_is_among_them() {
    for (i, a) in ALL.iter().enumerate() {
        for b in ALL.iter().skip(i + 1) {
            assert_ne!(a.name, b.name);
        }
    }
    assert!(ALL.iter().any(|board| board.name == BOARD.name));
}

#[test]
fn no_pin_is_used_twice() {
    for board in ALL {
        let pins = all_pins(&board);
        for (i, (a, what_a)) in pins.iter().enumerate() {
            for (b, what_b) in pins.iter().skip(i + 1) {
                assert!(
                    (a.port, a.number) != (b.port, b.number),
                    "{}: {what_a} and {what_b} share a pin",
                    board.name
                );
            }
        }
    }
}

#[test]
fn the_swd_pins_are_pa13_and_pa14() {
    use crate::chip::pins::Port;
    for board in ALL {
        let swd: Vec<(Port, u8)> = board.swd.iter().map(|p| (p.port, p.number)).collect();
        assert_eq!(swd, [(Port::A, 13), (Port::A, 14)], "{}", board.name);
    }
}

#[test]
fn timer_channels_are_distinct_and_groups_share_no_timer() {
    for board in ALL {
        let outputs: Vec<Output> = board.outputs().to_vec();
        for (i, a) in outputs.iter().enumerate() {
            assert!((1..=4).contains(&a.channel));
            for b in outputs.iter().skip(i + 1) {
                assert!(
                    (a.timer, a.channel) != (b.timer, b.channel),
                    "{}",
                    board.name
                );
            }
        }
        // The swash servos share a rate; the tail and the ESC have timers of their own,
        // so their rates are set independently.
        let swash = [
            board.servos[0].timer,
            board.servos[1].timer,
            board.servos[2].timer,
        ];
        assert!(!swash.contains(&board.servos[3].timer), "{}", board.name);
        assert!(!swash.contains(&board.esc.timer), "{}", board.name);
        assert_ne!(board.servos[3].timer, board.esc.timer, "{}", board.name);
        let swash_hz = board.frame_hz(swash[0]);
        assert!(swash.iter().all(|t| board.frame_hz(*t) == swash_hz));
    }
}

#[test]
fn every_started_timer_drives_an_output_and_is_started_once() {
    for board in ALL {
        let timers: Vec<OutputTimer> = board.output_timers.iter().map(|t| t.timer).collect();
        for (i, timer) in timers.iter().enumerate() {
            assert!(!timers[i + 1..].contains(timer), "{}", board.name);
            assert!(
                board.outputs().iter().any(|o| o.timer == *timer),
                "{}: {timer:?} drives nothing",
                board.name
            );
        }
    }
}

#[test]
fn alternate_functions_match_the_peripherals() {
    // Datasheet Table 9: TIM1/2 AF1, TIM3..5 AF2, TIM8..11 AF3, SPI1/2 AF5,
    // USART1..3 AF7; chip select and data ready are plain GPIOs.
    for board in ALL {
        for output in board.outputs() {
            assert_eq!(output.pin.af, output.timer.af(), "{}", board.name);
        }
        for spi in [board.imu.sck, board.imu.miso, board.imu.mosi] {
            assert_eq!(spi.af, 5, "{}", board.name);
        }
        for gpio in [board.imu.cs, board.imu.int] {
            assert_eq!(gpio.af, 0, "{}", board.name);
        }
        for usart in [board.link_tx, board.link_rx, board.sbus_rx, board.log_tx] {
            assert_eq!(usart.af, 7, "{}", board.name);
        }
    }
}

#[test]
fn the_usarts_sit_on_pins_that_carry_them() {
    use crate::chip::pins::Port;
    // Datasheet Table 9: the AF7 pins of USART1 TX/RX, USART2 RX and USART3 TX.
    let on = |pin: Pin, allowed: &[(Port, u8)]| allowed.contains(&(pin.port, pin.number));
    for board in ALL {
        assert!(on(board.link_tx, &[(Port::A, 9), (Port::B, 6)]));
        assert!(on(board.link_rx, &[(Port::A, 10), (Port::B, 7)]));
        assert!(on(board.sbus_rx, &[(Port::A, 3)]));
        assert!(on(board.log_tx, &[(Port::B, 10), (Port::C, 10)]));
        assert!(on(board.imu.sck, &[(Port::A, 5), (Port::B, 3)]));
        assert!(on(board.imu.miso, &[(Port::A, 6), (Port::B, 4)]));
        assert!(on(board.imu.mosi, &[(Port::A, 7), (Port::B, 5)]));
    }
}

#[test]
fn no_output_sits_on_the_imu_spi() {
    for board in ALL {
        let imu = [
            board.imu.sck,
            board.imu.miso,
            board.imu.mosi,
            board.imu.cs,
            board.imu.int,
        ];
        for output in board.outputs() {
            assert!(!imu
                .iter()
                .any(|p| (p.port, p.number) == (output.pin.port, output.pin.number)));
        }
    }
}

/// Betaflight's `alignSensors` (`src/main/sensors/boardalignment.c`), the cases the
/// boards' targets name: the chip's (x, y, z) to the board's (forward, left, up).
fn betaflight_align(align: &str, [x, y, z]: [f32; 3]) -> [f32; 3] {
    match align {
        "CW90_DEG" => [y, -x, z],
        "CW270_DEG_FLIP" => [-y, -x, -z],
        other => panic!("alignment {other} not transcribed"),
    }
}

/// ArduPilot's `Vector3::rotate` for `ROTATION_PITCH_180_YAW_270`: the chip's (x, y, z)
/// to the board's (forward, right, down).
fn ardupilot_pitch_180_yaw_270([x, y, z]: [f32; 3]) -> [f32; 3] {
    [y, x, -z]
}

#[test]
fn each_board_carries_its_imu_as_its_published_definitions_say() {
    // Betaflight's frame is (forward, left, up): (forward, right, down) negates the last two.
    let from_betaflight = |align: &str, chip: [f32; 3]| {
        let [f, l, u] = betaflight_align(align, chip);
        [f, -l, -u]
    };
    let published: [(&str, &str); 2] = [
        ("SpeedyBee F405 V4", "CW90_DEG"),
        ("Matek F405-TE", "CW270_DEG_FLIP"),
    ];
    assert_eq!(
        published.len(),
        ALL.len(),
        "every board has its definition here"
    );
    let chip = [0.3, -1.7, 2.9];
    for board in ALL {
        let (_, align) = published
            .iter()
            .find(|(name, _)| *name == board.name)
            .expect("board listed");
        let body = board.imu_mounting.orientation().to_body(chip);
        assert_eq!(body, from_betaflight(align, chip), "{}", board.name);
    }
    // The SpeedyBee F405 V4's ArduPilot hwdef says the same as its Betaflight target.
    assert_eq!(
        speedybee_f405_v4::BOARD
            .imu_mounting
            .orientation()
            .to_body(chip),
        ardupilot_pitch_180_yaw_270(chip)
    );
}
