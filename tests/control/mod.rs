//! Sections 2 and 5, Figures 8 and 10: the hip controller, the sensor front end and the bolter
//! (its current sensing, A/B handshake and statistics), and the paper's hardware facts
//! (spec/hardware.toml).

mod bolter_current;
mod bolter_handshake;
mod bolter_statistics;
mod control_hip;
mod sensors;
