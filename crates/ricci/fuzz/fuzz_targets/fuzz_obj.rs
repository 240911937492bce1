//! Fuzz the OBJ reader: any bytes give a polygon soup or an error, never a panic; an
//! accepted surface survives the builder, topology, and a write → read round trip.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ricci::mesh::io::Format;

fuzz_target!(|data: &[u8]| {
    ricci_fuzz::check(data, Format::Obj);
});
