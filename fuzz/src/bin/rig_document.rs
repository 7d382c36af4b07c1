//! AFL++ target: [`sinew_fuzz::rig_document`].
fn main() {
    afl::fuzz!(|data: &[u8]| sinew_fuzz::rig_document(data));
}
