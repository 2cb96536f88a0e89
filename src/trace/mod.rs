//! Traces: MCAP files holding a scene, ball sweeps and expected outcomes.

pub mod messages;
