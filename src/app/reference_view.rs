//! The error views in the viewer (`--view error`, `absolute-error`,
//! `signed-error`): the frame on show against its reference, mapped by
//! `display::error_view`. The reference is B of the A|B pair when the split
//! is on and B's image has A's size, else the scene's `[render] reference`
//! file. Without either the shaded image stays on show and the legend says
//! why. The worker renders these views shaded, so the inspector and the
//! probe keep reading linear radiance.

use crate::display::error_view::{error_image, ErrorKind, ErrorMap};
use crate::display::DisplaySettings;
use crate::math::Radiance;
use std::path::{Path, PathBuf};

/// What the error view on show was mapped from, for the legend.
#[derive(Clone, Debug, PartialEq)]
pub enum Mapped {
    /// Mapped against `source` with `map`.
    Against { source: String, map: ErrorMap },
    /// Not mapped: the shaded image is on show, for this reason.
    Unmapped(String),
}

#[derive(Default)]
pub struct ReferenceView {
    /// The scene's reference image, read once per path (or why it could not be).
    file: Option<(PathBuf, Result<(u32, u32, Vec<Radiance>), String>)>,
    /// What the image on show was mapped for: A's version, B's version (0:
    /// no B) and the view's kind.
    key: Option<(u64, u64, ErrorKind)>,
    pub mapped: Option<Mapped>,
}

impl ReferenceView {
    /// Whether the image for `key` is already on show.
    pub fn is_current(&self, key: (u64, u64, ErrorKind)) -> bool {
        self.key == Some(key)
    }

    /// Forgets the mapping (another view, another scene).
    pub fn clear(&mut self) {
        self.key = None;
        self.mapped = None;
    }

    /// The 8-bit image of `a` (width, height, linear pixels) in the error
    /// view `kind` against `b` (B's image, when the split is on) or the
    /// scene's reference file, through the display transform; `None` when
    /// there is no reference of A's size (`mapped` then says why).
    #[allow(clippy::too_many_arguments)]
    pub fn map(&mut self, key: (u64, u64, ErrorKind), a: (u32, u32, &[Radiance]), b: Option<(u32, u32, Vec<Radiance>)>, b_label: &str, scene_reference: Option<&Path>, display: &DisplaySettings, scene_exposure: f32) -> Option<Vec<u8>> {
        self.key = Some(key);
        let (w, h, pixels) = a;
        let (source, truth) = match (b, scene_reference) {
            (Some((bw, bh, b)), _) if (bw, bh) == (w, h) && b.len() == pixels.len() => (format!("B ({b_label})"), b),
            (Some(_), _) => {
                self.mapped = Some(Mapped::Unmapped("B's image is still a preview of another size".into()));
                return None;
            }
            (None, Some(path)) => match self.read(path) {
                Ok((rw, rh, r)) if (*rw, *rh) == (w, h) => (path.display().to_string(), r.clone()),
                Ok((rw, rh, _)) => {
                    self.mapped = Some(Mapped::Unmapped(format!("the reference {} is {rw}x{rh}, the image {w}x{h}", path.display())));
                    return None;
                }
                Err(e) => {
                    self.mapped = Some(Mapped::Unmapped(e.clone()));
                    return None;
                }
            },
            (None, None) => {
                self.mapped = Some(Mapped::Unmapped("no reference: turn on A|B (B) or set [render] reference in the scene".into()));
                return None;
            }
        };
        let (image, map) = error_image(key.2, pixels, &truth);
        self.mapped = Some(Mapped::Against { source, map });
        Some(crate::display::image_rgb8(&image, display.scale(scene_exposure), display.tonemap, display.gamma))
    }

    /// The scene's reference file, read the first time it is asked for.
    fn read(&mut self, path: &Path) -> &Result<(u32, u32, Vec<Radiance>), String> {
        if self.file.as_ref().is_none_or(|(p, _)| p != path) {
            let image = crate::image_io::load_image(path).map(|i| (i.width, i.height, i.pixels));
            self.file = Some((path.to_path_buf(), image));
        }
        &self.file.as_ref().expect("just read").1
    }
}
