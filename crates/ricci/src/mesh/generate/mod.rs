//! Procedural surfaces of good triangle quality (test and demo inputs).
