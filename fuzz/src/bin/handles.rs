//! AFL++ target: [`sinew_fuzz::handles`].
fn main() {
    afl::fuzz!(|data: &[u8]| sinew_fuzz::handles(data));
}
