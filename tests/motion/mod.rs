//! Section 6, Tables 5 and 6, Figure 9: the map, plans, estimation and the sequencer.

mod motion_estimate;
mod motion_estimate_oracle;
mod motion_map;
mod motion_plan_lengths;
mod motion_sequencer;
