//! Unit tests of the layered readers on small files built here; files written by real art
//! tools are tested in tests/layered.rs.

use super::*;
