//! AFL++ target: [`sinew_fuzz::scribbles`].
fn main() {
    afl::fuzz!(|data: &[u8]| sinew_fuzz::scribbles(data));
}
