//! AFL++ target: [`sinew_fuzz::batch_manifest`].
fn main() {
    // Its folder of inputs, made before AFL++ forks the runs.
    sinew_fuzz::batch_folder();
    afl::fuzz!(|data: &[u8]| sinew_fuzz::batch_manifest(data));
}
