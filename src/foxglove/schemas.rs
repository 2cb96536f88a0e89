//! The JSON Schemas embedded in the Foxglove output's schema records.
//!
//! `foxglove.SceneUpdate` and `foxglove.Log` are copies of the `jsonschema`
//! exports of the npm package `@foxglove/schemas` 2.1.0 (MIT License, see
//! `schemas/foxglove/LICENSE`); `tests/foxglove/validate.mjs --check-copies`
//! checks that they equal the package's. `sweeptrace.SweepNumbers` is this
//! project's own.

/// `foxglove.SceneUpdate`.
pub const SCENE_UPDATE_SCHEMA_JSON: &str = include_str!("../../schemas/foxglove/SceneUpdate.json");
/// `foxglove.Log`.
pub const LOG_SCHEMA_JSON: &str = include_str!("../../schemas/foxglove/Log.json");
/// `sweeptrace.SweepNumbers` (the Plot panel's channel).
pub const SWEEP_NUMBERS_SCHEMA_JSON: &str = include_str!("../../schemas/sweep_numbers.schema.json");

/// Schema name of the 3D scene channels.
pub const SCENE_UPDATE_SCHEMA: &str = "foxglove.SceneUpdate";
/// Schema name of the decisions channel.
pub const LOG_SCHEMA: &str = "foxglove.Log";
/// Schema name of the numbers channel.
pub const SWEEP_NUMBERS_SCHEMA: &str = "sweeptrace.SweepNumbers";
/// Schema encoding of every channel.
pub const SCHEMA_ENCODING: &str = "jsonschema";
/// Message encoding of every channel.
pub const MESSAGE_ENCODING: &str = "json";
