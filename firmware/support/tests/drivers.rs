//! The sensor drivers against embedded-hal-mock's I2C: the exact bus traffic (addresses,
//! command and register bytes, write and read lengths), the decoding of recorded answers, and
//! that bus failures and "no magnet" come back as errors. The mock panics on any transfer it
//! was not told to expect, and `done()` on any it expected that did not happen.

use embedded_hal::i2c::ErrorKind;
use embedded_hal_mock::eh1::i2c::{Mock, Transaction as Tx};
use mmic_fw_support::drivers::{ads7828, encoder, mpu6000, Error};

const BUS: Error<ErrorKind> = Error::Bus(ErrorKind::Other);

// ---- ADS7828 ----

/// The datasheet's single-ended table: SD = 1, C2 C1 C0 = 000, 100, 001, 101, 010, 110, 011,
/// 111 for CH0..CH7, PD1 PD0 = 11 (internal reference and converter on).
const ADS_COMMANDS: [u8; 8] = [0x8C, 0xCC, 0x9C, 0xDC, 0xAC, 0xEC, 0xBC, 0xFC];

#[test]
fn ads7828_command_byte_of_every_channel() {
    for (ch, &want) in ADS_COMMANDS.iter().enumerate() {
        assert_eq!(ads7828::command(ch as u8), want, "CH{ch}");
    }
}

#[test]
fn ads7828_read_all_converts_ch0_to_ch7_in_order() {
    let answers: [[u8; 2]; 8] = [
        [0x00, 0x00],
        [0x0A, 0xAA],
        [0x01, 0x23],
        [0x0F, 0xFF],
        [0x08, 0x00],
        [0x0B, 0xD6],
        [0x00, 0x01],
        [0x07, 0xFF],
    ];
    let exp: Vec<Tx> = (0..8)
        .map(|ch| Tx::write_read(0x48, vec![ADS_COMMANDS[ch]], answers[ch].to_vec()))
        .collect();
    let mut adc = ads7828::Ads7828::new(Mock::new(&exp), ads7828::ADDRESS);
    let codes = adc.read_all();
    adc.release().done();
    assert_eq!(codes, Ok([0, 0x0AAA, 0x0123, 4095, 2048, 3030, 1, 0x07FF]));
}

#[test]
fn ads7828_single_channel_at_a_strapped_address() {
    let exp = [Tx::write_read(0x4B, vec![0xEC], vec![0x0C, 0x34])];
    let mut adc = ads7828::Ads7828::new(Mock::new(&exp), 0x4B);
    let code = adc.read(5);
    adc.release().done();
    assert_eq!(code, Ok(0x0C34));
}

#[test]
fn ads7828_no_channel_8_and_no_traffic() {
    let mut adc = ads7828::Ads7828::new(Mock::new(&[]), ads7828::ADDRESS);
    let code = adc.read(8);
    adc.release().done();
    assert_eq!(code, Err(Error::Channel(8)));
}

#[test]
fn ads7828_bus_error_is_an_error_and_stops_the_sweep() {
    let mut exp: Vec<Tx> = (0..3)
        .map(|ch| Tx::write_read(0x48, vec![ADS_COMMANDS[ch]], vec![0x01, 0x00]))
        .collect();
    exp.push(Tx::write_read(0x48, vec![ADS_COMMANDS[3]], vec![0, 0]).with_error(ErrorKind::Other));
    let mut adc = ads7828::Ads7828::new(Mock::new(&exp), ads7828::ADDRESS);
    let codes = adc.read_all();
    adc.release().done();
    assert_eq!(codes, Err(BUS));
}

#[test]
fn ads7828_upper_nibble_set_is_a_frame_error_not_a_code() {
    let exp = [Tx::write_read(0x48, vec![0x8C], vec![0xFF, 0xFF])];
    let mut adc = ads7828::Ads7828::new(Mock::new(&exp), ads7828::ADDRESS);
    let code = adc.read(0);
    adc.release().done();
    assert_eq!(code, Err(Error::Frame(0xFFFF)));
}

// ---- MPU-6000 ----

fn mpu_init_traffic() -> Vec<Tx> {
    vec![
        Tx::write_read(0x68, vec![0x75], vec![0x68]), // WHO_AM_I
        Tx::write(0x68, vec![0x6B, 0x01]),            // PWR_MGMT_1: awake, PLL on X gyro
        Tx::write(0x68, vec![0x1C, 0x00]),            // ACCEL_CONFIG: ±2 g
    ]
}

#[test]
fn mpu6000_init_checks_who_am_i_wakes_and_sets_2g() {
    let mut imu = mpu6000::Mpu6000::new(Mock::new(&mpu_init_traffic()), mpu6000::ADDRESS);
    let r = imu.init();
    imu.release().done();
    assert_eq!(r, Ok(()));
}

#[test]
fn mpu6000_wrong_who_am_i_is_an_error_before_any_write() {
    let exp = [Tx::write_read(0x68, vec![0x75], vec![0x70])];
    let mut imu = mpu6000::Mpu6000::new(Mock::new(&exp), mpu6000::ADDRESS);
    let r = imu.init();
    imu.release().done();
    assert_eq!(r, Err(Error::WhoAmI(0x70)));
}

#[test]
fn mpu6000_bus_error_while_waking_is_an_error() {
    let mut exp = mpu_init_traffic();
    exp.truncate(2);
    exp[1] = Tx::write(0x68, vec![0x6B, 0x01]).with_error(ErrorKind::Other);
    let mut imu = mpu6000::Mpu6000::new(Mock::new(&exp), mpu6000::ADDRESS);
    let r = imu.init();
    imu.release().done();
    assert_eq!(r, Err(BUS));
}

#[test]
fn mpu6000_accel_is_one_big_endian_signed_burst() {
    let exp = [
        // 1 g along −Y, +10 on X, 0x4000 = +1 g on Z.
        Tx::write_read(0x69, vec![0x3B], vec![0x00, 0x0A, 0xC0, 0x00, 0x40, 0x00]),
        // The extremes and −1.
        Tx::write_read(0x69, vec![0x3B], vec![0x80, 0x00, 0x7F, 0xFF, 0xFF, 0xFF]),
    ];
    let mut imu = mpu6000::Mpu6000::new(Mock::new(&exp), 0x69);
    let a = imu.accel();
    let b = imu.accel();
    imu.release().done();
    assert_eq!(a, Ok([10, -16384, 16384]));
    assert_eq!(b, Ok([i16::MIN, i16::MAX, -1]));
}

#[test]
fn mpu6000_bus_error_on_accel_is_an_error() {
    let exp = [Tx::write_read(0x68, vec![0x3B], vec![0; 6]).with_error(ErrorKind::Other)];
    let mut imu = mpu6000::Mpu6000::new(Mock::new(&exp), mpu6000::ADDRESS);
    let a = imu.accel();
    imu.release().done();
    assert_eq!(a, Err(BUS));
}

// ---- hip encoder ----

fn encoder_traffic(status: u8, angle: [u8; 2]) -> Vec<Tx> {
    vec![
        Tx::write_read(0x36, vec![0x0B], vec![status]),
        Tx::write_read(0x36, vec![0x0C], angle.to_vec()),
    ]
}

fn encoder_angle(exp: &[Tx]) -> Result<u16, Error<ErrorKind>> {
    let mut enc = encoder::HipEncoder::new(Mock::new(exp), encoder::ADDRESS);
    let r = enc.angle();
    enc.release().done();
    r
}

#[test]
fn encoder_reads_status_then_the_12_bit_raw_angle() {
    assert_eq!(
        encoder_angle(&encoder_traffic(0x20, [0x0F, 0xFF])),
        Ok(4095)
    );
    assert_eq!(encoder_angle(&encoder_traffic(0x20, [0x00, 0x00])), Ok(0));
    assert_eq!(
        encoder_angle(&encoder_traffic(0x20, [0x08, 0x01])),
        Ok(2049)
    );
    // The unused upper nibble is masked off.
    assert_eq!(
        encoder_angle(&encoder_traffic(0x20, [0xF4, 0x00])),
        Ok(1024)
    );
}

#[test]
fn encoder_detected_but_weak_or_strong_magnet_still_reads() {
    assert_eq!(encoder_angle(&encoder_traffic(0x30, [0x01, 0x00])), Ok(256));
    assert_eq!(encoder_angle(&encoder_traffic(0x28, [0x01, 0x00])), Ok(256));
}

#[test]
fn encoder_no_magnet_is_an_error_and_the_angle_is_not_read() {
    for status in [0x00, 0x10, 0x08, 0xC7] {
        let exp = [Tx::write_read(0x36, vec![0x0B], vec![status])];
        assert_eq!(
            encoder_angle(&exp),
            Err(Error::NoMagnet(status & 0x38)),
            "STATUS {status:#04x}"
        );
    }
}

#[test]
fn encoder_status_masks_to_md_ml_mh() {
    let exp = [Tx::write_read(0x36, vec![0x0B], vec![0xFF])];
    let mut enc = encoder::HipEncoder::new(Mock::new(&exp), encoder::ADDRESS);
    let s = enc.status();
    enc.release().done();
    assert_eq!(s, Ok(encoder::MD | encoder::ML | encoder::MH));
    assert_eq!(encoder::MD | encoder::ML | encoder::MH, 0x38);
}

#[test]
fn encoder_bus_errors_are_errors() {
    let exp = [Tx::write_read(0x36, vec![0x0B], vec![0x20]).with_error(ErrorKind::Other)];
    assert_eq!(encoder_angle(&exp), Err(BUS));
    let mut exp = encoder_traffic(0x20, [0x08, 0x00]);
    exp[1] = Tx::write_read(0x36, vec![0x0C], vec![0x08, 0x00]).with_error(ErrorKind::Other);
    assert_eq!(encoder_angle(&exp), Err(BUS));
}

// ---- into the library ----

#[test]
fn drivers_feed_the_library_front_end() {
    use mmic::sensors::frontend::{Frontend, Raw};
    use mmic::units::{Axis, Sign};
    // 10.0 V battery on CH0 (code 2730 of 15 V), −1 g on Y, hip at half a turn.
    let mut exp: Vec<Tx> = (0..8)
        .map(|ch| {
            let code: [u8; 2] = if ch == 0 { [0x0A, 0xAA] } else { [0, 0] };
            Tx::write_read(0x48, vec![ADS_COMMANDS[ch]], code.to_vec())
        })
        .collect();
    exp.push(Tx::write_read(0x68, vec![0x3B], vec![0, 10, 0xC0, 0, 0, 0]));
    exp.extend(encoder_traffic(0x20, [0x08, 0x00]));
    let mock = Mock::new(&exp);
    let mut adc = ads7828::Ads7828::new(mock.clone(), ads7828::ADDRESS);
    let mut imu = mpu6000::Mpu6000::new(mock.clone(), mpu6000::ADDRESS);
    let mut enc = encoder::HipEncoder::new(mock.clone(), encoder::ADDRESS);
    let (codes, accel, angle) = (adc.read_all(), imu.accel(), enc.angle());
    mock.clone().done();
    assert_eq!(codes, Ok([2730, 0, 0, 0, 0, 0, 0, 0]));
    assert_eq!((accel, angle), (Ok([10, -16384, 0]), Ok(2048)));
    let mut f = Frontend::<50>::new(Default::default());
    let out = f.push(&Raw {
        adc: codes.ok(),
        accel: accel.ok(),
        encoder: angle.ok(),
    });
    assert_eq!(out.electrical.v_bat, 10_000);
    assert_eq!(
        out.gravity.map(|g| (g.axis, g.sign)),
        Some((Axis::Y, Sign::Negative))
    );
    assert_eq!(out.hip.map(|h| h.centidegrees()), Some(18_000));
    assert!(!out.lost.any());
}
