//! AFL++ target: [`sinew_fuzz::spine_script`].
fn main() {
    // Its folder of PNGs, made before AFL++ forks the runs.
    sinew_fuzz::spine_folder();
    afl::fuzz!(|data: &[u8]| sinew_fuzz::spine_script(data));
}
