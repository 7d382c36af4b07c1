//! AFL++ target: [`sinew_fuzz::bvh`].
fn main() {
    afl::fuzz!(|data: &[u8]| sinew_fuzz::bvh(data));
}
