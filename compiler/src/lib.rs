//! The kiln scene compiler: import → scene IR → plan → bake → write.
//!
//! The binary `kiln` only parses arguments and dispatches to [`commands`].

pub mod cli;
pub mod commands;
pub mod exit;
pub mod output;
