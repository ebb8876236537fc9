//! The kiln scene compiler: import → scene IR → plan → bake → write.
//!
//! The binary `kiln` only parses arguments and dispatches to [`commands`].

pub mod analyze;
pub mod bake;
pub mod bench_scenes;
pub mod cache;
pub mod cli;
pub mod clobber;
pub mod commands;
pub mod exit;
pub mod import;
pub mod ir;
pub mod output;
pub mod pipeline;
pub mod progress;
pub mod raycheck;
pub mod settings;
pub mod shading;
pub mod untrusted;
pub mod warnings;
