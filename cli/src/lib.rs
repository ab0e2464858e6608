//! # fricont-cli — the `fricont` program and the case study
//!
//! The binary `fricont` (trace a problem directory, generate rectangles, run the case
//! study) and the case study of the founding paper with its figures ([`casestudy`]).
//! The exchange format and the reports are in `fricont-exchange`.

pub mod casestudy;
