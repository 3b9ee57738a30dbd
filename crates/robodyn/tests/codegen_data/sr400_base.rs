// Base parameters of the Acma SR400 (Table 10.2), written by hand from the chapter's listing
// (Example 10.2). Shared by the codegen tests with `include!`. The OCR of the listing is garbled
// in places; the grouping equations below follow the step-by-step derivation of Example 10.2:
// - ZZR1: the listing swaps d2 and d3; from the derivation (YYR2 and MR2 grouped into ZZR1),
//   ZZR1 = IA1 + ZZ1 + YY2 + YY3 + XX7 + YY8 + d4^2 MR4 + d3^2 (M3..M6) + d2^2 (M2..M8);
// - the listing's `XZR_1 = XZ_1 + YZ_1` is XZR3 = XZ3 + YZ7 (J7 grouped into J3, 7A3 = rot(z, pi/2));
// - MYR3 keeps the term -d8 MX8 / d3 of the link-8 step (dropped in the listing).
#[allow(dead_code)]
pub fn table_10_2() -> robodyn::codegen::BaseParameters {
    use robodyn::codegen::{BaseParameters, GroupedParameter};
    use robodyn::Expr;
    let g = |replaces: &str, name: &str, e: &str| GroupedParameter {
        replaces: replaces.into(),
        name: name.into(),
        expr: Expr::parse(e).unwrap(),
    };
    let grouped =
        vec![
        g(
            "ZZ1",
            "ZZR1",
            "IA1 + ZZ1 + YY2 + YY3 + XX7 + YY8 + d4^2*(M4 + M5 + M6) + d3^2*(M3 + M4 + M5 + M6) \
             + d2^2*(M2 + M3 + M4 + M5 + M6) + d2^2*(M7 + M8)",
        ),
        g("XX2", "XXR2", "XX2 - YY2 + XX8 - YY8 - d3^2*(M3 + M4 + M5 + M6)"),
        g("XY2", "XYR2", "XY2 + XY8"),
        g("XZ2", "XZR2", "XZ2 + XZ8 - d3*MZ3"),
        g("YZ2", "YZR2", "YZ2 + YZ8"),
        g("ZZ2", "ZZR2", "IA2 + ZZ2 + ZZ8 + d3^2*(M3 + M4 + M5 + M6)"),
        g("MX2", "MXR2", "MX2 + MX8 + d3*(M3 + M4 + M5 + M6)"),
        g(
            "XX3",
            "XXR3",
            "XX3 - YY3 + YY4 - XX7 + YY7 - d4^2*(M4 + M5 + M6) + 2*MZ4*RL4 \
             + (M4 + M5 + M6)*RL4^2 + d8^2*M8",
        ),
        g("XY3", "XYR3", "XY3 - XY7 - d4*MZ4 - d4*RL4*(M4 + M5 + M6)"),
        g("XZ3", "XZR3", "XZ3 + YZ7"),
        g("YZ3", "YZR3", "YZ3 - XZ7 + d8*MZ8"),
        g(
            "ZZ3",
            "ZZR3",
            "IA7 + ZZ3 + YY4 + ZZ7 + d8^2*M8 + 2*MZ4*RL4 + (M4 + M5 + M6)*(d4^2 + RL4^2)",
        ),
        g("MX3", "MXR3", "MX3 + d4*(M4 + M5 + M6)"),
        g("MY3", "MYR3", "MY3 - d8*MX8/d3 + MZ4 + (M4 + M5 + M6)*RL4"),
        g("XX4", "XXR4", "XX4 - YY4 + YY5"),
        g("ZZ4", "ZZR4", "ZZ4 + YY5"),
        g("MY4", "MYR4", "MY4 - MZ5"),
        g("XX5", "XXR5", "XX5 - YY5 + YY6"),
        g("ZZ5", "ZZR5", "ZZ5 + YY6"),
        g("MY5", "MYR5", "MY5 + MZ6"),
        g("XX6", "XXR6", "XX6 - YY6"),
        g("MX7", "MXR7", "MX7 - d8*MX8/d3 + d8*M8"),
    ];
    let zero = [
        "XX1 XY1 XZ1 YY1 YZ1 MX1 MY1 MZ1 M1 IA1",
        "YY2 MZ2 M2 IA2",
        "YY3 MZ3 M3 IA3",
        "YY4 MZ4 M4",
        "YY5 MZ5 M5",
        "YY6 MZ6 M6",
        "XX7 XY7 XZ7 YY7 YZ7 ZZ7 MZ7 M7 IA7",
        "XX8 XY8 XZ8 YY8 YZ8 ZZ8 MX8 MZ8 M8 IA8",
    ]
    .iter()
    .flat_map(|s| s.split_whitespace().map(str::to_string))
    .collect();
    BaseParameters { grouped, zero }
}
