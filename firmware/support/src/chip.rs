//! Everything that differs between the chips: the pin map. ESP32-C3 by default, ESP32-C6
//! with the feature `c6` (README.md has the table and the wiring notes).

use esp_hal::gpio::AnyPin;
pub use esp_hal::gpio::Pin;

/// A side's pins: the I2C bus (ADS7828, MPU-6000, hip encoder), the servo pulses (arm,
/// gripper, hip; board B leaves the hip unused), the bolter driver (direction, translate
/// enable, rotate enable), the ADG1604's A0/A1, the 7.4 V regulator enable, the A–B serial
/// line (TX, RX) and the switches (arm contracted, bolter at home).
#[allow(missing_docs)]
pub struct Pins {
    pub sda: AnyPin<'static>,
    pub scl: AnyPin<'static>,
    pub servos: [AnyPin<'static>; 3],
    pub bolter: [AnyPin<'static>; 3],
    pub mux: [AnyPin<'static>; 2],
    pub regulator: AnyPin<'static>,
    pub uart: [AnyPin<'static>; 2],
    pub switches: [AnyPin<'static>; 2],
}

/// The chip's name, for the start-up line.
pub const CHIP: &str = if cfg!(feature = "c6") {
    "ESP32-C6"
} else {
    "ESP32-C3"
};

/// Takes the pin map's pins out of `esp_hal::init`'s peripherals (ESP32-C3: GPIO0–10 and
/// 18–21; 18/19 are the USB pins, so the USB console stops at start-up).
#[cfg(not(feature = "c6"))]
#[macro_export]
macro_rules! take_pins {
    ($p:ident) => {{
        use $crate::chip::Pin as _;
        $crate::chip::Pins {
            sda: $p.GPIO4.degrade(),
            scl: $p.GPIO5.degrade(),
            servos: [$p.GPIO6.degrade(), $p.GPIO7.degrade(), $p.GPIO10.degrade()],
            bolter: [$p.GPIO0.degrade(), $p.GPIO1.degrade(), $p.GPIO3.degrade()],
            mux: [$p.GPIO18.degrade(), $p.GPIO19.degrade()],
            regulator: $p.GPIO2.degrade(),
            uart: [$p.GPIO21.degrade(), $p.GPIO20.degrade()],
            switches: [$p.GPIO8.degrade(), $p.GPIO9.degrade()],
        }
    }};
}

/// Takes the pin map's pins out of `esp_hal::init`'s peripherals (ESP32-C6).
#[cfg(feature = "c6")]
#[macro_export]
macro_rules! take_pins {
    ($p:ident) => {{
        use $crate::chip::Pin as _;
        $crate::chip::Pins {
            sda: $p.GPIO6.degrade(),
            scl: $p.GPIO7.degrade(),
            servos: [
                $p.GPIO18.degrade(),
                $p.GPIO19.degrade(),
                $p.GPIO20.degrade(),
            ],
            bolter: [
                $p.GPIO21.degrade(),
                $p.GPIO22.degrade(),
                $p.GPIO23.degrade(),
            ],
            mux: [$p.GPIO0.degrade(), $p.GPIO1.degrade()],
            regulator: $p.GPIO2.degrade(),
            uart: [$p.GPIO10.degrade(), $p.GPIO11.degrade()],
            switches: [$p.GPIO3.degrade(), $p.GPIO14.degrade()],
        }
    }};
}
