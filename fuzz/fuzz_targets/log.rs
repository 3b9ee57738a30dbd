//! Fuzz identification's log reader and the identification of what it accepts: see
//! `robodyn::identification::fuzz_checks::check_log`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    robodyn::identification::fuzz_checks::check_log(data);
});
