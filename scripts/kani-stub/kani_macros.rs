//! Type-checking stub of the `kani` attribute macros (NOT a verifier); see scripts/kani-typecheck.sh.
extern crate proc_macro;
use proc_macro::TokenStream;
#[proc_macro_attribute]
pub fn proof(_a: TokenStream, i: TokenStream) -> TokenStream { i }
#[proc_macro_attribute]
pub fn unwind(_a: TokenStream, i: TokenStream) -> TokenStream { i }
