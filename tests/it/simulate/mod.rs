//! The simulator: the intersection experiment, the pipeline's sampling, scenario files and the statistics.

mod experiment;
mod pipeline;
mod scenarios;
mod stats;
