//! The egui viewer (issue 4). Placeholder until the viewer lands.

/// Opens the viewer on `scene` (a built-in name, `.toml` or `.obj`; `None`:
/// the default scene). With `screenshot`, waits for the full-quality frame,
/// saves a screenshot of the whole window there and exits.
pub fn run(scene: Option<String>, screenshot: Option<std::path::PathBuf>) -> Result<(), String> {
    let _ = (scene, screenshot);
    Err("the viewer is not built yet".into())
}
