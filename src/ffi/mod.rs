//! The C ABI (`include/fricont.h`): the only module with `unsafe`. It converts between C
//! and the Rust API and adds nothing mathematical.
//!
//! * [`status`]: `fricont_status` (0 ok, positive outcomes, negative errors in bands),
//!   the enumerations passed as `int32_t`, versions, the thread-local last error.
//! * [`problem`]: the `fricont_problem` handle (A, N, T in CSR; F, g, r setters; build).
//! * [`path`]: the `fricont_path` handle (loads with C callbacks, stepping, queries).
//! * `boundary`: the panic boundary around every export and the pointer/slice checks.
//!
//! Conventions: every C symbol is `fricont_*`, every macro and enumerator `FRICONT_*`;
//! handles are created by `fricont_X_new*(…, fricont_X **out)` and freed by
//! `fricont_X_free` (NULL is a no-op); inputs are read during the call and copied;
//! outputs go to caller buffers with explicit lengths; statuses taken as input are
//! `int32_t`. The header is generated from this module by cbindgen (`cbindgen.toml`,
//! `scripts/gen-header.sh`) and checked for staleness by `tests/header.rs`.

pub(crate) mod boundary;

// The header lists the items in this order: statuses first, then the problem, the path.
pub mod status;

pub mod problem;

pub mod path;

#[cfg(test)]
mod tests;
