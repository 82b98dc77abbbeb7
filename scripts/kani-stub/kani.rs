//! Type-checking stub of the `kani` crate's surface (NOT a verifier).
pub use kani_macros::{proof, unwind};
pub trait Arbitrary { fn any() -> Self; }
macro_rules! prim { ($($t:ty),*) => { $(impl Arbitrary for $t { fn any() -> Self { Default::default() } })* } }
prim!(u8, u16, u32, u64, u128, usize, i8, i16, i32, i64, bool);
impl<T: Arbitrary, const N: usize> Arbitrary for [T; N] { fn any() -> Self { core::array::from_fn(|_| T::any()) } }
macro_rules! tuple { ($($t:ident),*) => { impl<$($t: Arbitrary),*> Arbitrary for ($($t,)*) { fn any() -> Self { ($($t::any(),)*) } } } }
tuple!(A); tuple!(A,B); tuple!(A,B,C); tuple!(A,B,C,D); tuple!(A,B,C,D,E); tuple!(A,B,C,D,E,F); tuple!(A,B,C,D,E,F,G); tuple!(A,B,C,D,E,F,G,H);
pub fn any<T: Arbitrary>() -> T { T::any() }
pub fn assume(_c: bool) {}
#[macro_export]
macro_rules! cover { ($c:expr, $m:literal) => { let _ = $c; }; }
