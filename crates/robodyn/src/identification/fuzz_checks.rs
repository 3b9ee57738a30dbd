//! The properties the identification fuzz targets (`fuzz/`) check on every input, shared with
//! the test that replays the inputs they found. Each function panics when the property fails.
