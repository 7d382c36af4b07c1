//! AFL++ target: [`sinew_fuzz::ora`].
fn main() {
    // The fixture's PNG layers, read before AFL++ forks the runs.
    sinew_fuzz::ora_zip(b"");
    afl::fuzz!(|data: &[u8]| sinew_fuzz::ora(data));
}
