//! AFL++ target: [`sinew_fuzz::pose`].
fn main() {
    afl::fuzz!(|data: &[u8]| sinew_fuzz::pose(data));
}
