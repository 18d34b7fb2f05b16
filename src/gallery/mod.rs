//! The stress gallery: scenes that each provoke one known failure of a
//! rendering method, with the setting that causes it and the setting that
//! cures it, both measured as wrong pixels against a truth image.
//!
//! - `cases`: the table of cases (add a case by adding an entry there);
//! - `measure`: rendering a case's settings and counting wrong pixels;
//! - `sheet`: the contact sheet (failing | cured, one row per case).

pub mod cases;
pub mod measure;
pub mod sheet;

pub use cases::{cases, case_by_name, GalleryCase, Setting};
pub use measure::{judge, measure_case, render_case, render_setting, wrong_pixels, CaseImages, CaseResult, SettingResult};
