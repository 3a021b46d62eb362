//! Driver, emulator and monitor tests: the driver against `embedded-hal-mock` (exact SPI
//! bytes) and against the emulator (values, statistics, faults, reset).

use embedded_hal_mock::eh1::delay::{CheckedDelay, NoopDelay, Transaction as DelayTransaction};
use embedded_hal_mock::eh1::spi::{Mock as SpiMock, Transaction as SpiTransaction};

use super::calibration::{CalibrationConfig, CalibrationStatus, GyroCalibration};
use super::emulator::{Fault, Icm42688Emulator, Imperfections, Vibration, RESET_VALUES};
use super::registers::*;
use super::*;

const DEG: f32 = core::f32::consts::PI / 180.0;
const MS: u64 = 1_000_000;

// ---------------------------------------------------------------- mock: exact bytes

/// One register write: `[address, value]` in its own transaction.
fn write(address: u8, value: u8) -> [SpiTransaction<u8>; 3] {
    [
        SpiTransaction::transaction_start(),
        SpiTransaction::write_vec(vec![address, value]),
        SpiTransaction::transaction_end(),
    ]
}

/// One burst read: `address | 0x80`, then the response bytes.
fn read(address: u8, response: &[u8]) -> [SpiTransaction<u8>; 4] {
    [
        SpiTransaction::transaction_start(),
        SpiTransaction::write(address | 0x80),
        SpiTransaction::read_vec(response.to_vec()),
        SpiTransaction::transaction_end(),
    ]
}

/// The init sequence up to and including the WHO_AM_I read, which returns `id`.
fn init_head(id: u8) -> Vec<SpiTransaction<u8>> {
    let mut expected = Vec::new();
    expected.extend(write(0x76, 0x00)); // REG_BANK_SEL: bank 0
    expected.extend(write(0x11, 0x01)); // DEVICE_CONFIG: soft reset
    expected.extend(read(0x75, &[id])); // WHO_AM_I
    expected
}

/// The init sequence after WHO_AM_I, with `readback` as the chip's answer.
fn init_tail(readback: [u8; 5]) -> Vec<SpiTransaction<u8>> {
    let mut expected = Vec::new();
    expected.extend(write(0x14, 0x03)); // INT_CONFIG: INT1 push-pull, active high
    expected.extend(write(0x64, 0x00)); // INT_CONFIG1: INT_ASYNC_RESET off
    expected.extend(write(0x65, 0x08)); // INT_SOURCE0: data-ready on INT1
    expected.extend(write(0x4F, 0x06)); // GYRO_CONFIG0: ±2000 °/s, 1 kHz
    expected.extend(write(0x50, 0x06)); // ACCEL_CONFIG0: ±16 g, 1 kHz
    expected.extend(write(0x52, 0x41)); // GYRO_ACCEL_CONFIG0: accel 100 Hz, gyro 250 Hz
    expected.extend(write(0x4E, 0x0F)); // PWR_MGMT0: gyro and accel low-noise
    expected.extend(read(0x4E, &readback)); // read back 0x4E..=0x52
    expected
}

#[test]
fn init_sends_the_exact_byte_sequence() {
    let mut expected = init_head(0x47);
    expected.extend(init_tail([0x0F, 0x06, 0x06, 0x16, 0x41]));
    expected.extend(read(0x2D, &[0x18])); // INT_STATUS: clear RESET_DONE, DATA_RDY
    let mut spi = SpiMock::new(&expected);
    let mut delay = CheckedDelay::new(&[
        DelayTransaction::delay_ms(1),
        DelayTransaction::delay_ms(45),
    ]);
    let mut imu = Icm42688::new(spi.clone());
    assert_eq!(imu.init(&mut delay), Ok(()));
    spi.done();
    delay.done();
}

#[test]
fn init_stops_at_a_wrong_who_am_i() {
    let mut spi = SpiMock::new(&init_head(0x00));
    let mut delay = CheckedDelay::new(&[DelayTransaction::delay_ms(1)]);
    let mut imu = Icm42688::new(spi.clone());
    assert_eq!(imu.init(&mut delay), Err(ImuError::WrongId(0x00)));
    spi.done();
    delay.done();
}

#[test]
fn init_reports_a_register_that_does_not_read_back() {
    let mut expected = init_head(0x47);
    // ACCEL_CONFIG0 reads 0x00 (MOSI bit errors, say).
    expected.extend(init_tail([0x0F, 0x06, 0x00, 0x16, 0x41]));
    let mut spi = SpiMock::new(&expected);
    let mut imu = Icm42688::new(spi.clone());
    assert_eq!(
        imu.init(&mut NoopDelay),
        Err(ImuError::ConfigMismatch {
            register: 0x50,
            expected: 0x06,
            found: 0x00
        })
    );
    assert_eq!(ImuError::WrongId(0).fault(), ImuFault::Missing);
    spi.done();
}

#[test]
fn read_is_one_14_byte_burst_from_0x1d_decoded_big_endian() {
    // temperature +1325 (35.0 °C), accel (+2048, −2048, −2048) (±1 g),
    // gyro (+16384, −1, +32767).
    let block = [
        0x05, 0x2D, 0x08, 0x00, 0xF8, 0x00, 0xF8, 0x00, 0x40, 0x00, 0xFF, 0xFF, 0x7F, 0xFF,
    ];
    let mut spi = SpiMock::new(&read(0x1D, &block));
    let mut imu = Icm42688::new(spi.clone());
    let sample = imu.read().expect("read");
    spi.done();
    assert_eq!(
        sample.raw,
        RawSample {
            temperature: 1325,
            accel: [2048, -2048, -2048],
            gyro: [16384, -1, 32767],
        }
    );
    let g = GRAVITY_M_S2;
    assert_eq!(sample.accel_m_s2, [g, -g, -g]);
    assert_eq!(
        sample.gyro_rad_s,
        [
            16384.0 * GYRO_RAD_S_PER_LSB,
            -GYRO_RAD_S_PER_LSB,
            32767.0 * GYRO_RAD_S_PER_LSB
        ]
    );
    // 16384 LSB = 1000 °/s.
    assert!((sample.gyro_rad_s[0] - 1000.0 * DEG).abs() < 1e-5);
    assert!((sample.temperature_c - (1325.0 / 132.48 + 25.0)).abs() < 1e-6);
    assert!((sample.temperature_c - 35.0).abs() < 0.01);
}

#[test]
fn data_ready_is_int_status_bit_3_and_poll_checks_who_am_i_when_not_ready() {
    let mut expected = Vec::new();
    expected.extend(read(0x2D, &[0x08]));
    expected.extend(read(0x2D, &[0x10]));
    // poll, not ready, WHO_AM_I fine: Ok(None)
    expected.extend(read(0x2D, &[0x00]));
    expected.extend(read(0x75, &[0x47]));
    // poll, not ready, WHO_AM_I gone
    expected.extend(read(0x2D, &[0x00]));
    expected.extend(read(0x75, &[0x00]));
    let mut spi = SpiMock::new(&expected);
    let mut imu = Icm42688::new(spi.clone());
    assert_eq!(imu.data_ready(), Ok(true));
    assert_eq!(imu.data_ready(), Ok(false));
    assert_eq!(imu.poll(), Ok(None));
    assert_eq!(imu.poll(), Err(ImuError::WrongId(0x00)));
    spi.done();
}

// ---------------------------------------------------------------- orientation

fn all_signed_permutations() -> Vec<[SignedAxis; 3]> {
    use SignedAxis::*;
    let axes = [PosX, NegX, PosY, NegY, PosZ, NegZ];
    let mut out = Vec::new();
    for a in axes {
        for b in axes {
            for c in axes {
                out.push([a, b, c]);
            }
        }
    }
    out
}

#[test]
fn orientation_accepts_exactly_the_24_rotations() {
    let rotations: Vec<Orientation> = all_signed_permutations()
        .into_iter()
        .filter_map(Orientation::new)
        .collect();
    assert_eq!(rotations.len(), 24);
    let v = [1.0, -2.0, 3.5];
    for o in &rotations {
        assert_eq!(o.to_chip(o.to_body(v)), v);
        assert_eq!(o.to_body(o.to_chip(v)), v);
    }
    use SignedAxis::*;
    assert_eq!(
        Orientation::new([PosX, PosY, PosZ]),
        Some(Orientation::IDENTITY)
    );
    assert_eq!(
        Orientation::new([PosX, NegY, NegZ]),
        Some(Orientation::TOP_UP_X_FORWARD)
    );
    // A reflection and a repeated axis.
    assert_eq!(Orientation::new([PosX, PosY, NegZ]), None);
    assert_eq!(Orientation::new([PosX, PosX, PosZ]), None);
    // Chip x pointing right, chip y forward, chip z up: body = (y, x, −z).
    let yaw = Orientation::new([PosY, PosX, NegZ]).expect("rotation");
    assert_eq!(yaw.to_body([1.0, 2.0, 3.0]), [2.0, 1.0, -3.0]);
    assert_eq!(Orientation::TOP_UP_X_FORWARD.to_body(v), [1.0, 2.0, -3.5]);
}

// ---------------------------------------------------------------- emulator

/// A driver on an initialised emulator.
fn ready(imperfections: Imperfections) -> Icm42688<Icm42688Emulator> {
    let mut imu = Icm42688::new(Icm42688Emulator::new(imperfections));
    imu.init(&mut NoopDelay).expect("init");
    imu
}

/// One 1 ms step of the emulator, then one poll.
fn tick(imu: &mut Icm42688<Icm42688Emulator>) -> Result<Option<ImuSample>, ImuError> {
    imu.spi_mut().advance_ns(MS);
    imu.poll()
}

/// `n` consecutive samples, one per 1 ms step.
fn samples(imu: &mut Icm42688<Icm42688Emulator>, n: usize) -> Vec<ImuSample> {
    (0..n)
        .map(|i| {
            tick(imu)
                .expect("poll")
                .unwrap_or_else(|| panic!("no sample at step {i}"))
        })
        .collect()
}

#[test]
fn init_succeeds_and_configures_the_emulator() {
    let imu = ready(Imperfections::BENCH);
    let emu = imu.release();
    assert_eq!(emu.register(0, PWR_MGMT0), 0x0F);
    assert_eq!(emu.register(0, GYRO_CONFIG0), 0x06);
    assert_eq!(emu.register(0, ACCEL_CONFIG0), 0x06);
    assert_eq!(emu.register(0, GYRO_ACCEL_CONFIG0), 0x41);
    assert_eq!(emu.register(0, INT_SOURCE0), 0x08);
    assert_eq!(emu.register(0, INT_CONFIG), 0x03);
    assert_eq!(emu.register(0, INT_CONFIG1), 0x00);
    assert_eq!(emu.register(0, INT_STATUS), 0x00, "cleared by init");
    assert_eq!(emu.sample_period_ns(), Some(MS));
    // The chip's registers read through the driver match.
    let mut imu = Icm42688::new(emu);
    assert_eq!(imu.who_am_i(), Ok(0x47));
    assert_eq!(imu.read_register(GYRO_CONFIG0), Ok(0x06));
}

#[test]
fn init_recovers_a_chip_left_in_another_bank() {
    let mut emu = Icm42688Emulator::new(Imperfections::IDEAL);
    let mut imu = Icm42688::new(&mut emu);
    imu.write_register(REG_BANK_SEL, 1).expect("write");
    // Bank 1 holds no WHO_AM_I: reads 0x00 there.
    assert_eq!(imu.who_am_i(), Ok(0x00));
    assert_eq!(imu.init(&mut NoopDelay), Ok(()));
    assert_eq!(emu.bank(), 0);
    assert_eq!(emu.register(0, PWR_MGMT0), 0x0F);
}

#[test]
fn reads_reproduce_the_truth_within_half_an_lsb_without_imperfections() {
    for orientation in [
        Orientation::IDENTITY,
        Orientation::TOP_UP_X_FORWARD,
        Orientation::new([SignedAxis::NegY, SignedAxis::PosZ, SignedAxis::NegX]).expect("rot"),
    ] {
        let mut imu = ready(Imperfections::IDEAL);
        imu.set_orientation(orientation);
        imu.spi_mut().set_mounting(orientation);
        let mut rng = crate::noise::Pcg32::new(7);
        for _ in 0..500 {
            let gyro: [f32; 3] = core::array::from_fn(|_| (rng.next_unit() - 0.5) * 60.0);
            let accel: [f32; 3] = core::array::from_fn(|_| (rng.next_unit() - 0.5) * 300.0);
            let temperature = 20.0 + 40.0 * rng.next_unit();
            imu.spi_mut().set_truth(gyro, accel);
            imu.spi_mut().set_temperature(temperature);
            let s = tick(&mut imu).expect("poll").expect("sample");
            for (read, truth) in s.gyro_rad_s.iter().zip(gyro) {
                assert!(
                    (read - truth).abs() <= 0.51 * GYRO_RAD_S_PER_LSB,
                    "gyro {read} vs {truth}"
                );
            }
            for (read, truth) in s.accel_m_s2.iter().zip(accel) {
                assert!(
                    (read - truth).abs() <= 0.51 * ACCEL_M_S2_PER_LSB,
                    "accel {read} vs {truth}"
                );
            }
            assert!((s.temperature_c - temperature).abs() <= 0.5 / 132.48 + 1e-5);
        }
    }
}

#[test]
fn a_chip_mounted_top_up_reads_plus_g_without_its_orientation() {
    let mut imu = ready(Imperfections::IDEAL);
    imu.spi_mut().set_mounting(Orientation::TOP_UP_X_FORWARD);
    // At rest, level: body specific force (0, 0, −g), p = 0.1 rad/s.
    imu.spi_mut()
        .set_truth([0.1, 0.0, 0.0], [0.0, 0.0, -GRAVITY_M_S2]);
    let s = tick(&mut imu).expect("poll").expect("sample");
    assert_eq!(s.raw.accel, [0, 0, 2048]); // chip z up: +1 g
    assert!((s.accel_m_s2[2] - GRAVITY_M_S2).abs() < 1e-3);
    imu.set_orientation(Orientation::TOP_UP_X_FORWARD);
    let s = tick(&mut imu).expect("poll").expect("sample");
    assert!((s.accel_m_s2[2] + GRAVITY_M_S2).abs() < 1e-3);
    assert!((s.gyro_rad_s[0] - 0.1).abs() <= GYRO_RAD_S_PER_LSB);
}

/// Mean and standard deviation.
fn stats(values: impl Iterator<Item = f32>) -> (f64, f64) {
    let v: Vec<f64> = values.map(f64::from).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

#[test]
fn bias_scale_error_and_noise_statistics_appear_as_configured() {
    let imperfections = Imperfections {
        gyro_bias_rad_s: [0.3 * DEG, -0.2 * DEG, 0.1 * DEG],
        accel_bias_m_s2: [0.05, -0.08, 0.12],
        gyro_noise_rad_s: 5e-3,
        accel_noise_m_s2: 0.05,
        gyro_scale_error: [0.0, 0.01, -0.02],
        accel_scale_error: [0.0, 0.0, 0.005],
        ..Imperfections::IDEAL
    };
    let mut imu = ready(imperfections);
    let truth_gyro = [0.0, 1.0, 0.5];
    let truth_accel = [0.0, 0.0, -GRAVITY_M_S2];
    imu.spi_mut().set_truth(truth_gyro, truth_accel);
    let n = 20_000;
    let data = samples(&mut imu, n);
    let sqrt_n = (n as f64).sqrt();
    for (axis, truth) in truth_gyro.into_iter().enumerate() {
        let (mean, std) = stats(data.iter().map(|s| s.gyro_rad_s[axis]));
        let expected = f64::from(1.0 + imperfections.gyro_scale_error[axis]) * f64::from(truth)
            + f64::from(imperfections.gyro_bias_rad_s[axis]);
        // Noise plus quantisation: σ² + LSB²/12.
        let lsb = f64::from(GYRO_RAD_S_PER_LSB);
        let sigma = (5e-3_f64.powi(2) + lsb * lsb / 12.0).sqrt();
        assert!(
            (mean - expected).abs() < 4.0 * sigma / sqrt_n,
            "gyro {axis}: mean {mean}, expected {expected}"
        );
        assert!(
            (std / sigma - 1.0).abs() < 0.03,
            "gyro {axis}: std {std}, σ {sigma}"
        );
    }
    for (axis, truth) in truth_accel.into_iter().enumerate() {
        let (mean, std) = stats(data.iter().map(|s| s.accel_m_s2[axis]));
        let expected = f64::from(1.0 + imperfections.accel_scale_error[axis]) * f64::from(truth)
            + f64::from(imperfections.accel_bias_m_s2[axis]);
        let lsb = f64::from(ACCEL_M_S2_PER_LSB);
        let sigma = (0.05_f64.powi(2) + lsb * lsb / 12.0).sqrt();
        assert!(
            (mean - expected).abs() < 4.0 * sigma / sqrt_n,
            "accel {axis}: mean {mean}, expected {expected}"
        );
        assert!(
            (std / sigma - 1.0).abs() < 0.03,
            "accel {axis}: std {std}, σ {sigma}"
        );
    }
}

/// Amplitude of the `frequency_hz` line in `values` sampled every 1 ms (a whole number of
/// cycles long): |2/N Σ x e^{−jωt}|.
fn line_amplitude(values: &[f32], frequency_hz: f64) -> f64 {
    let n = values.len() as f64;
    let (mut i, mut q) = (0.0, 0.0);
    for (k, &x) in values.iter().enumerate() {
        let phase = 2.0 * core::f64::consts::PI * frequency_hz * k as f64 * 1e-3;
        i += f64::from(x) * phase.cos();
        q += f64::from(x) * phase.sin();
    }
    2.0 / n * (i * i + q * q).sqrt()
}

#[test]
fn rotor_vibration_lines_appear_at_their_frequencies_and_amplitudes() {
    let preset = Imperfections::TREX700L_ROTOR_RUNNING;
    let lines: Vec<Vibration> = preset.vibration.to_vec();
    assert_eq!(
        lines.iter().map(|v| v.frequency_hz).collect::<Vec<_>>(),
        [35.0, 70.0, 157.5]
    );
    let mut imu = ready(Imperfections {
        vibration: preset.vibration,
        ..Imperfections::IDEAL
    });
    // 2 s: whole cycles of 35, 70 and 157.5 Hz.
    let data = samples(&mut imu, 2000);
    for line in &lines {
        for axis in 0..3 {
            let gyro: Vec<f32> = data.iter().map(|s| s.gyro_rad_s[axis]).collect();
            let found = line_amplitude(&gyro, f64::from(line.frequency_hz));
            let expected = f64::from(line.gyro_rad_s[axis]);
            assert!(
                (found - expected).abs() < 0.02 * expected + 2e-4,
                "{} Hz gyro {axis}: {found} vs {expected}",
                line.frequency_hz
            );
            let accel: Vec<f32> = data.iter().map(|s| s.accel_m_s2[axis]).collect();
            // The accel z mean (−g) does not leak into the lines: whole cycles.
            let found = line_amplitude(&accel, f64::from(line.frequency_hz));
            let expected = f64::from(line.accel_m_s2[axis]);
            assert!(
                (found - expected).abs() < 0.02 * expected + 2e-3,
                "{} Hz accel {axis}: {found} vs {expected}",
                line.frequency_hz
            );
        }
    }
    // Nothing at 50 Hz.
    let accel_z: Vec<f32> = data.iter().map(|s| s.accel_m_s2[2]).collect();
    assert!(line_amplitude(&accel_z, 50.0) < 2e-3);
}

#[test]
fn the_same_seed_gives_the_same_bytes_and_another_seed_does_not() {
    let run = |seed: u64| -> Vec<u8> {
        let mut emu = Icm42688Emulator::new(Imperfections {
            seed,
            ..Imperfections::TREX700L_ROTOR_RUNNING
        });
        let mut imu = Icm42688::new(&mut emu);
        imu.init(&mut NoopDelay).expect("init");
        let mut bytes = Vec::new();
        for _ in 0..200 {
            imu.spi_mut().advance_ns(MS);
            let mut block = [0u8; SENSOR_BLOCK_LEN];
            imu.read_registers(TEMP_DATA1, &mut block).expect("read");
            bytes.extend(block);
        }
        bytes
    };
    let a = run(42);
    assert_eq!(a, run(42));
    assert_ne!(a, run(43));
}

#[test]
fn quantisation_and_saturation_at_full_scale() {
    let mut imu = ready(Imperfections::IDEAL);
    // 40 rad/s > 2000 °/s (34.9 rad/s); 200 m/s² > 16 g (156.9 m/s²).
    imu.spi_mut()
        .set_truth([40.0, -40.0, 0.0], [200.0, -200.0, 0.0]);
    let s = tick(&mut imu).expect("poll").expect("sample");
    assert_eq!(s.raw.gyro, [32767, -32767, 0]);
    assert_eq!(s.raw.accel, [32767, -32767, 0]);
    assert!(s.raw.any_axis_saturated());
    // Half an LSB rounds away from zero, just below rounds down.
    let lsb = GYRO_RAD_S_PER_LSB;
    imu.spi_mut()
        .set_truth([10.6 * lsb, -10.4 * lsb, 0.0], [0.0; 3]);
    let s = tick(&mut imu).expect("poll").expect("sample");
    assert_eq!(s.raw.gyro, [11, -10, 0]);
}

#[test]
fn the_emulator_honours_the_full_scale_selection() {
    let mut imu = ready(Imperfections::IDEAL);
    // ±250 °/s (FS_SEL 011) and ±2 g (FS_SEL 011), still 1 kHz.
    imu.write_register(GYRO_CONFIG0, (0b011 << 5) | 0x06)
        .expect("write");
    imu.write_register(ACCEL_CONFIG0, (0b011 << 5) | 0x06)
        .expect("write");
    imu.spi_mut()
        .set_truth([1.0, 0.0, 0.0], [0.0, 0.0, -GRAVITY_M_S2]);
    let s = tick(&mut imu).expect("poll").expect("sample");
    // 1 rad/s = 57.2958 °/s; 32768/250 LSB per °/s → 7509.7 → 7510.
    assert_eq!(s.raw.gyro, [7510, 0, 0]);
    // 1 g at ±2 g: 16384 LSB.
    assert_eq!(s.raw.accel, [0, 0, -16384]);
    // 3 g saturates at ±2 g.
    imu.spi_mut()
        .set_truth([0.0; 3], [0.0, 0.0, -3.0 * GRAVITY_M_S2]);
    let s = tick(&mut imu).expect("poll").expect("sample");
    assert_eq!(s.raw.accel, [0, 0, -32767]);
}

#[test]
fn data_ready_is_set_per_sample_and_cleared_on_read() {
    let mut imu = ready(Imperfections::IDEAL);
    assert_eq!(imu.data_ready(), Ok(false));
    // 0.5 ms: no sample yet (first one 1 ms after power-on).
    imu.spi_mut().advance_ns(MS / 2);
    assert_eq!(imu.data_ready(), Ok(false));
    imu.spi_mut().advance_ns(MS / 2);
    assert_eq!(imu.data_ready(), Ok(true));
    assert_eq!(imu.data_ready(), Ok(false), "cleared by the read");
    assert_eq!(imu.spi_mut().advance(0.005), 5);
    assert_eq!(imu.data_ready(), Ok(true));
    assert_eq!(imu.spi_mut().advance(f32::NAN), 0);
    assert_eq!(imu.spi_mut().advance(-1.0), 0);
    // Without advancing time, produce_sample still sets data-ready.
    assert!(imu.spi_mut().produce_sample());
    assert_eq!(imu.data_ready(), Ok(true));
}

#[test]
fn soft_reset_restores_the_defaults() {
    let mut imu = ready(Imperfections::BENCH);
    samples(&mut imu, 10);
    imu.write_register(DEVICE_CONFIG, DEVICE_CONFIG_SOFT_RESET)
        .expect("write");
    {
        let emu = imu.spi_mut();
        for (address, value) in RESET_VALUES {
            assert_eq!(emu.register(0, address), value, "register {address:#04x}");
        }
        for address in 0..0x80u8 {
            if RESET_VALUES.iter().all(|&(a, _)| a != address) {
                assert_eq!(emu.register(0, address), 0, "register {address:#04x}");
            }
        }
        assert_eq!(emu.sample_period_ns(), None, "sensors off");
        assert_eq!(emu.advance(0.01), 0);
    }
    // Sensor data read "no data"; RESET_DONE is set, then cleared by the read.
    let s = imu.read().expect("read");
    assert_eq!(s.raw.gyro, [DATA_INVALID; 3]);
    assert_eq!(s.raw.accel, [DATA_INVALID; 3]);
    assert_eq!(imu.read_register(INT_STATUS), Ok(INT_STATUS_RESET_DONE));
    assert_eq!(imu.read_register(INT_STATUS), Ok(0));
    // And init brings it back.
    assert_eq!(imu.init(&mut NoopDelay), Ok(()));
    assert_eq!(samples(&mut imu, 3).len(), 3);
}

#[test]
fn auto_increment_wraps_and_read_only_registers_ignore_writes() {
    let mut imu = ready(Imperfections::IDEAL);
    let mut buffer = [0u8; 4];
    // 0x7E, 0x7F, then 0x00, 0x01.
    imu.read_registers(0x7E, &mut buffer).expect("read");
    assert_eq!(buffer, [0, 0, 0, 0]);
    imu.read_registers(0x74, &mut buffer).expect("read");
    assert_eq!(buffer, [0x00, 0x47, 0x00, 0x00]);
    imu.write_register(WHO_AM_I, 0x12).expect("write");
    assert_eq!(imu.who_am_i(), Ok(0x47));
    imu.write_register(GYRO_DATA_X1, 0x12).expect("write");
    assert_eq!(imu.spi_mut().register(0, GYRO_DATA_X1), 0x80);
    // A burst write auto-increments too: GYRO_CONFIG0, ACCEL_CONFIG0.
    use embedded_hal::spi::SpiDevice;
    imu.spi_mut()
        .write(&[GYRO_CONFIG0, 0x26, 0x46])
        .expect("write");
    assert_eq!(imu.read_register(GYRO_CONFIG0), Ok(0x26));
    assert_eq!(imu.read_register(ACCEL_CONFIG0), Ok(0x46));
}

// ---------------------------------------------------------------- faults

/// A healthy run: `n` polls, no fault.
fn healthy(imu: &mut Icm42688<Icm42688Emulator>, monitor: &mut ImuMonitor, n: usize) {
    for i in 0..n {
        let poll = tick(imu);
        assert!(matches!(poll, Ok(Some(_))), "poll {i}: {poll:?}");
        assert_eq!(monitor.feed(&poll), None, "poll {i}");
    }
}

/// Polls until the monitor reports a fault (at most 100): the fault and the number of
/// polls it took.
fn polls_to_fault(
    imu: &mut Icm42688<Icm42688Emulator>,
    monitor: &mut ImuMonitor,
) -> (ImuFault, usize) {
    for polls in 1..=100 {
        if let Some(fault) = monitor.feed(&tick(imu)) {
            return (fault, polls);
        }
    }
    panic!("no fault in 100 polls");
}

#[test]
fn a_healthy_chip_raises_no_fault_even_with_the_rotor_running() {
    for imperfections in [Imperfections::BENCH, Imperfections::TREX700L_ROTOR_RUNNING] {
        let mut imu = ready(imperfections);
        let mut monitor = ImuMonitor::default();
        healthy(&mut imu, &mut monitor, 5000);
    }
}

#[test]
fn each_injected_fault_is_detected_within_its_documented_latency() {
    let limits = MonitorLimits::DEFAULT;
    let cases = [
        // Stuck: the first frozen read repeats the last good one, so the run of
        // identical reads is one long already: N − 1 polls.
        (
            Fault::Stuck,
            ImuFault::Stuck,
            usize::from(limits.stuck_reads) - 1,
        ),
        (
            Fault::Saturate,
            ImuFault::Saturated,
            usize::from(limits.saturated_reads),
        ),
        (Fault::Missing, ImuFault::Missing, 1),
        (Fault::BusError, ImuFault::Missing, 1),
    ];
    for (inject, expected, latency) in cases {
        let mut imu = ready(Imperfections::BENCH);
        let mut monitor = ImuMonitor::default();
        healthy(&mut imu, &mut monitor, 100);
        imu.spi_mut().set_fault(inject);
        let (fault, polls) = polls_to_fault(&mut imu, &mut monitor);
        assert_eq!((fault, polls), (expected, latency), "{inject:?}");
        // Latched.
        assert_eq!(monitor.feed(&tick(&mut imu)), Some(expected));
        // Healing the chip does not clear the monitor; reset does.
        imu.spi_mut().set_fault(Fault::None);
        assert_eq!(monitor.feed(&tick(&mut imu)), Some(expected));
        monitor.reset();
        healthy(&mut imu, &mut monitor, 50);
    }
}

#[test]
fn a_brown_out_is_detected_as_not_ready() {
    let mut imu = ready(Imperfections::BENCH);
    let mut monitor = ImuMonitor::default();
    healthy(&mut imu, &mut monitor, 100);
    // The chip resets: sensors off, WHO_AM_I still answers.
    imu.spi_mut().soft_reset();
    let (fault, polls) = polls_to_fault(&mut imu, &mut monitor);
    assert_eq!(
        (fault, polls),
        (
            ImuFault::NotReady,
            usize::from(MonitorLimits::DEFAULT.not_ready_polls)
        )
    );
    // Re-initialised, it runs again.
    imu.init(&mut NoopDelay).expect("init");
    monitor.reset();
    healthy(&mut imu, &mut monitor, 50);
}

#[test]
fn init_fails_on_each_missing_chip_fault() {
    let mut emu = Icm42688Emulator::new(Imperfections::BENCH);
    emu.set_fault(Fault::Missing);
    let mut imu = Icm42688::new(emu);
    assert_eq!(imu.init(&mut NoopDelay), Err(ImuError::WrongId(0x00)));
    imu.spi_mut().set_fault(Fault::BusError);
    assert_eq!(
        imu.init(&mut NoopDelay),
        Err(ImuError::Bus(embedded_hal::spi::ErrorKind::Other))
    );
    imu.spi_mut().set_fault(Fault::None);
    assert_eq!(imu.init(&mut NoopDelay), Ok(()));
}

// ---------------------------------------------------------------- monitor alone

fn raw(v: i16) -> RawSample {
    RawSample {
        temperature: 0,
        accel: [v, 1, 2],
        gyro: [3, 4, 5],
    }
}

#[test]
fn monitor_stuck_at_exactly_n_identical_reads() {
    let limits = MonitorLimits {
        stuck_reads: 4,
        ..MonitorLimits::DEFAULT
    };
    let mut m = ImuMonitor::new(limits);
    for _ in 0..3 {
        assert_eq!(m.feed_sample(&raw(7)), None);
    }
    // A change restarts the run.
    assert_eq!(m.feed_sample(&raw(8)), None);
    assert_eq!(m.feed_sample(&raw(8)), None);
    assert_eq!(m.feed_sample(&raw(8)), None);
    // Temperature is not part of the comparison.
    let mut warmer = raw(8);
    warmer.temperature = 100;
    assert_eq!(m.feed_sample(&warmer), Some(ImuFault::Stuck));
    // Not-ready polls in between do not break a run.
    let mut m = ImuMonitor::new(limits);
    for _ in 0..3 {
        m.feed_sample(&raw(1));
        m.feed_not_ready();
    }
    assert_eq!(m.feed_sample(&raw(1)), Some(ImuFault::Stuck));
}

#[test]
fn monitor_saturated_after_m_consecutive_reads_and_wins_over_stuck() {
    let mut m = ImuMonitor::default();
    let m_reads = MonitorLimits::DEFAULT.saturated_reads;
    let clipped = |i: u16| RawSample {
        temperature: 0,
        accel: [0, -32767, i16::try_from(i).unwrap_or(0)],
        gyro: [1, 2, 3],
    };
    for i in 1..m_reads {
        assert_eq!(m.feed_sample(&clipped(i)), None);
    }
    // One clean read resets the count.
    assert_eq!(m.feed_sample(&raw(0)), None);
    for i in 1..m_reads {
        assert_eq!(m.feed_sample(&clipped(i)), None);
    }
    assert_eq!(m.feed_sample(&clipped(99)), Some(ImuFault::Saturated));
    // −32768 (no data) counts as saturated as well.
    assert!(RawSample {
        accel: [i16::MIN, 0, 0],
        ..RawSample::default()
    }
    .any_axis_saturated());
    assert!(!raw(32766).any_axis_saturated());
    // Pinned output at full scale: saturated, reported before stuck.
    let mut m = ImuMonitor::new(MonitorLimits {
        stuck_reads: 3,
        saturated_reads: 3,
        not_ready_polls: 5,
    });
    let pinned = RawSample {
        temperature: 0,
        accel: [i16::MAX; 3],
        gyro: [i16::MAX; 3],
    };
    m.feed_sample(&pinned);
    m.feed_sample(&pinned);
    assert_eq!(m.feed_sample(&pinned), Some(ImuFault::Saturated));
}

#[test]
fn monitor_not_ready_after_k_polls_reset_by_a_sample_and_the_first_fault_latches() {
    let mut m = ImuMonitor::default();
    let k = MonitorLimits::DEFAULT.not_ready_polls;
    for _ in 1..k {
        assert_eq!(m.feed(&Ok(None)), None);
    }
    let sample = ImuSample {
        raw: raw(0),
        ..ImuSample::default()
    };
    assert_eq!(m.feed(&Ok(Some(sample))), None);
    for _ in 1..k {
        assert_eq!(m.feed(&Ok(None)), None);
    }
    assert_eq!(m.feed(&Ok(None)), Some(ImuFault::NotReady));
    // Latched: a later error does not replace it.
    assert_eq!(
        m.feed(&Err(ImuError::WrongId(0xFF))),
        Some(ImuFault::NotReady)
    );
    assert_eq!(m.fault(), Some(ImuFault::NotReady));
    m.reset();
    assert_eq!(m.fault(), None);
    assert_eq!(
        m.feed(&Err(ImuError::Bus(embedded_hal::spi::ErrorKind::Other))),
        Some(ImuFault::Missing)
    );
    // Zero limits act as one.
    let mut m = ImuMonitor::new(MonitorLimits {
        stuck_reads: 0,
        saturated_reads: 0,
        not_ready_polls: 0,
    });
    assert_eq!(m.feed_not_ready(), Some(ImuFault::NotReady));
}

// ---------------------------------------------------------------- calibration end to end

#[test]
fn boot_calibration_on_the_emulator_finds_the_bias_and_the_mounting_tilt() {
    let imperfections = Imperfections::BENCH;
    let mut imu = ready(imperfections);
    // The board sits 2° rolled right and 1° nose down.
    let (phi, theta) = (2.0 * DEG, -DEG);
    let g = GRAVITY_M_S2;
    let f = [
        g * theta.sin(),
        -g * phi.sin() * theta.cos(),
        -g * phi.cos() * theta.cos(),
    ];
    imu.spi_mut().set_truth([0.0; 3], f);
    let mut calibration = GyroCalibration::new(CalibrationConfig::DEFAULT);
    let mut monitor = ImuMonitor::default();
    let mut result = None;
    for i in 0..2000 {
        let poll = tick(&mut imu);
        assert_eq!(monitor.feed(&poll), None);
        let sample = poll.expect("poll").expect("sample");
        match calibration.feed(&sample) {
            CalibrationStatus::Collecting => {}
            CalibrationStatus::Done(bias) => {
                result = Some((i, bias));
                break;
            }
            other => panic!("sample {i}: {other:?}"),
        }
    }
    let (index, bias) = result.expect("calibration done");
    assert_eq!(index, 999, "one still window of 1000 samples");
    // Within 0.1 LSB of the configured bias (noise σ/√1000 ≈ 0.02 LSB).
    for (found, configured) in bias.gyro_rad_s.iter().zip(imperfections.gyro_bias_rad_s) {
        assert!(
            (found - configured).abs() < 0.1 * GYRO_RAD_S_PER_LSB,
            "bias {:?} vs {:?}",
            bias.gyro_rad_s,
            imperfections.gyro_bias_rad_s
        );
    }
    // The tilt, to 0.02° (the accelerometer scale errors of ±0.3 % skew it slightly).
    assert!((bias.roll_rad - phi).abs() < 0.02 * DEG, "{bias:?}");
    assert!((bias.pitch_rad - theta).abs() < 0.02 * DEG, "{bias:?}");
    assert!((bias.temperature_c - 25.0).abs() < 0.01);
}

#[test]
fn boot_calibration_restarts_when_the_aircraft_is_moved() {
    let mut imu = ready(Imperfections::BENCH);
    let mut calibration = GyroCalibration::default();
    for _ in 0..500 {
        let s = tick(&mut imu).expect("poll").expect("sample");
        assert_eq!(calibration.feed(&s), CalibrationStatus::Collecting);
    }
    // Someone picks the tail up: 10 °/s pitch for 50 ms. Every sample restarts (the
    // first on the deviation from the window mean, all on the 5 °/s rate limit).
    imu.spi_mut()
        .set_truth([0.0, 10.0 * DEG, 0.0], [0.0, 0.0, -GRAVITY_M_S2]);
    let moved = (0..50)
        .filter(|_| {
            let s = tick(&mut imu).expect("poll").expect("sample");
            matches!(calibration.feed(&s), CalibrationStatus::Moved(_))
        })
        .count();
    assert_eq!(moved, 50);
    assert_eq!(calibration.restarts(), 50);
    imu.spi_mut().set_truth([0.0; 3], [0.0, 0.0, -GRAVITY_M_S2]);
    let mut done_after = None;
    for i in 1..=1100 {
        let s = tick(&mut imu).expect("poll").expect("sample");
        if let CalibrationStatus::Done(_) = calibration.feed(&s) {
            done_after = Some(i);
            break;
        }
    }
    // A fresh window from the first still sample.
    assert_eq!(done_after, Some(1000));
}

#[test]
fn boot_calibration_does_not_accept_a_running_rotor() {
    let mut imu = ready(Imperfections::TREX700L_ROTOR_RUNNING);
    let mut calibration = GyroCalibration::default();
    let moved = (0..1000)
        .filter(|_| {
            let s = tick(&mut imu).expect("poll").expect("sample");
            matches!(calibration.feed(&s), CalibrationStatus::Moved(_))
        })
        .count();
    assert!(moved > 10, "{moved}");
    assert_eq!(calibration.result(), None);
}
