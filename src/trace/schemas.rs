//! The JSON Schema documents of the three channels, written into every trace.

/// JSON Schema of `/scene` messages (`sweeptrace.Scene`).
pub const SCENE_SCHEMA_JSON: &str = include_str!("../../schemas/scene.schema.json");
/// JSON Schema of `/sweep` messages (`sweeptrace.Sweep`).
pub const SWEEP_SCHEMA_JSON: &str = include_str!("../../schemas/sweep.schema.json");
/// JSON Schema of `/expected` messages (`sweeptrace.Outcome`).
pub const OUTCOME_SCHEMA_JSON: &str = include_str!("../../schemas/outcome.schema.json");
/// JSON Schema of `/contact` messages (`sweeptrace.Contact`).
pub(crate) const CONTACT_SCHEMA_JSON: &str = include_str!("../../schemas/contact.schema.json");
/// JSON Schema of `/expected_contacts` messages (`sweeptrace.Contacts`).
pub(crate) const CONTACTS_SCHEMA_JSON: &str = include_str!("../../schemas/contacts.schema.json");
/// Schema encoding of the three channels, in either message encoding (the
/// JSON Schemas describe the CBOR messages too: the same maps and fields).
pub const SCHEMA_ENCODING: &str = "jsonschema";
/// Value of `format_version` in the `sweeptrace` metadata record.
pub const FORMAT_VERSION: &str = "1";
/// Name of the metadata record written by this crate.
pub const METADATA_NAME: &str = "sweeptrace";
