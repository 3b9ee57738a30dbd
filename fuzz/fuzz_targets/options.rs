//! Fuzz identification's options (their validation, then identification of a valid log with
//! them): see `robodyn::identification::fuzz_checks::check_options`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    robodyn::identification::fuzz_checks::check_options(data);
});
