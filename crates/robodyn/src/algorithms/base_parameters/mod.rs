//! Base inertial parameters (§10.2.4, §10.3.4–10.3.6).
