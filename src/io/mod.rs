//! Files: the native rig document and images.
