//! AFL++ target: [`sinew_fuzz::psd`].
fn main() {
    afl::fuzz!(|data: &[u8]| sinew_fuzz::psd(data));
}
