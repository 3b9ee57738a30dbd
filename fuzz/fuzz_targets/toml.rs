//! Fuzz the toml reader (and, on what it accepts, both writers): see `robodyn::io::fuzz_checks`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    robodyn::io::fuzz_checks::check_robot_file(robodyn::io::Format::Toml, data);
});
