//! Shared fixtures of deflect's cross-crate tests, examples and benchmarks.

/// Path of a file shipped in the repository, from the workspace root.
pub fn repo_path(relative: &str) -> String {
    format!("{}/{relative}", env!("CARGO_MANIFEST_DIR"))
}

/// The shipped KR 300 R2500 model (URDF + Table 1 stiffnesses), chain base_link -> tcp.
pub fn kr300() -> deflect_core::SerialRobot {
    match deflect_core::SerialRobot::from_files(
        repo_path("robots/kr300/kr300_r2500.urdf"),
        repo_path("robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    ) {
        Ok(r) => r,
        Err(e) => panic!("the shipped KR 300 model must load: {e}"),
    }
}

/// A milling pose of the KR 300 model [rad]: flange pointing down, TCP 1.80 m in front of A1 and
/// 0.48 m above the base, tool axis horizontal.
pub const KR300_MILLING_POSE: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];

/// A 546 N milling force (the paper's largest) in the horizontal plane, base frame [N, N m].
pub const MILLING_WRENCH: [f64; 6] = [-386.1, 386.1, 0.0, 0.0, 0.0, 0.0];
