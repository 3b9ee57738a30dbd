//! Fuzz the state-table (CSV) reader: see `robodyn::io::fuzz_checks`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    robodyn::io::fuzz_checks::check_table(data);
});
