//! AFL++ target: [`sinew_fuzz::animations`].
fn main() {
    afl::fuzz!(|data: &[u8]| sinew_fuzz::animations(data));
}
