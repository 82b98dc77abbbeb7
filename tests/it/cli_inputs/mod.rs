//! What the command line reads and writes, under hostile input and conditions: bad files, flags and bytes, the validated boundary, outputs.

mod boundary;
mod hostile_input;
mod outputs;
mod reads;
