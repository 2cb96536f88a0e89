//! Tests of the C API: the C example compiled with the system compiler and
//! a Python `ctypes` script write traces that `check` passes, and bad calls
//! return error codes with messages instead of crashing. (That the
//! checked-in header is what cbindgen generates is checked by
//! `scripts/check_header.sh`, in CI.)

mod bad_calls;
mod engine;
mod programs;
