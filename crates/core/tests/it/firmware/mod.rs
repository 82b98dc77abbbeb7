//! The integer firmware side (`firmware::*`): the quantizer that builds tables, the codec and the integer checker.

mod build;
mod check;
mod codec;
mod head;
mod head_diff;
