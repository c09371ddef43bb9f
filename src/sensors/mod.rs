//! Sensor processing (Section 2): the 50-sample moving average every raw channel goes through,
//! the ADS7828 channel map and scaling to mV/mA, the IMU's gravity direction, and the hip
//! encoder's angle, and [`frontend`], which joins them for one side of the robot. Integer-only (the ESP32-C3 has no FPU).
//!
//! ```
//! use mmic::sensors::MovingAverage;
//! let mut f = MovingAverage::<50>::new();
//! f.push(100);
//! f.push(200);
//! assert_eq!(f.mean(), Some(150)); // before the window is full: the mean of what came
//! ```
// req: P2.5, P2.6, P2.9, P2.10

pub mod adc;
pub mod encoder;
mod filter;
pub mod frontend;
pub mod imu;

pub use filter::{Averages, MovingAverage};
