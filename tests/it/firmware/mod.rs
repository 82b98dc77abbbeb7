//! Firmware tables from profiles: the paper's tables, every preset's table and the header boundary.

mod boundary;
mod paper_tables;
