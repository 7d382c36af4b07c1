//! AFL++ target: [`sinew_fuzz::png_trace_mesh`].
fn main() {
    afl::fuzz!(|data: &[u8]| sinew_fuzz::png_trace_mesh(data));
}
