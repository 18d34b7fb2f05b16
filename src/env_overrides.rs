//! Every `PINHOLE_*` environment variable the program reads, in one place.
//! They exist for scripts and tests (screenshots, UI benchmarks, a cache
//! folder a test can own); nothing else reads them. Each is parsed here into
//! a typed value; one that does not parse is reported on stderr, naming the
//! variable, and ignored.
//!
//! | variable | what it does |
//! | --- | --- |
//! | `PINHOLE_RENDERER=NAME` | the viewer starts with this renderer (any `--renderer` name) |
//! | `PINHOLE_SPLIT=NAME` | the viewer shows the live view against this renderer (A\|B wipe); B keeps the settings as they are before the overrides below |
//! | `PINHOLE_VIEW=NAME` | the viewer's debug view (any `--view` name) |
//! | `PINHOLE_GAMMA=off` | the viewer shows linear values (`0`, `off`, `false`: off; anything else: on) |
//! | `PINHOLE_GI=MODE` | the viewer's indirect light (any `--gi` mode) |
//! | `PINHOLE_SPP=N` | the viewer's samples per pixel, 1 to 4096 |
//! | `PINHOLE_SELECT=X,Y` | the viewer selects this pixel for the inspector |
//! | `PINHOLE_ZOOM=Z` | the viewer magnifies the image (about the selected pixel, if any) |
//! | `PINHOLE_VERTICES=on` | the viewer draws the vertex overlay |
//! | `PINHOLE_GALLERY=CASE` | the viewer opens this stress-gallery case at its failing setting |
//! | `PINHOLE_COMPARE=on` | the viewer opens the Compare window and starts measuring |
//! | `PINHOLE_PANELS=camera,lights,materials,shading` | which side-panel sections are open (`none`: no side panel) |
//! | `PINHOLE_BENCH_UI=SECONDS[:still][:SPP]` | the viewer orbits (or stays still) for SECONDS, prints UI frames per second, and quits |
//! | `PINHOLE_CACHE_DIR=DIR` | where path-traced chart references are cached |

use crate::render::inspect::debug::View;
use crate::render::transport::gi::GiMode;
use std::path::PathBuf;

/// The viewer's overrides, as the environment gave them (`None`: not set,
/// or not understood).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewerOverrides {
    /// `PINHOLE_RENDERER`, by its full name.
    pub renderer: Option<&'static str>,
    /// `PINHOLE_SPLIT`, by its full name.
    pub split: Option<&'static str>,
    pub view: Option<View>,
    pub gamma: Option<bool>,
    pub gi: Option<GiMode>,
    pub spp: Option<u32>,
    pub select: Option<(i64, i64)>,
    pub zoom: Option<f32>,
    pub vertices: Option<bool>,
    pub gallery: Option<String>,
    pub compare: bool,
    pub panels: Option<OpenPanels>,
    /// `PINHOLE_BENCH_UI`, unparsed (the viewer's `UiBench::parse` reads it).
    pub bench_ui: Option<String>,
}

/// `PINHOLE_PANELS`: which side-panel sections are open.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpenPanels {
    pub side: bool,
    pub camera: bool,
    pub lights: bool,
    pub materials: bool,
    pub shading: bool,
}

impl ViewerOverrides {
    /// Reads every viewer variable from the environment.
    pub fn from_env() -> ViewerOverrides {
        ViewerOverrides::from_lookup(|k| std::env::var(k).ok())
    }

    /// Reads every viewer variable through `get` (the environment, or a table in tests).
    pub fn from_lookup(get: impl Fn(&str) -> Option<String>) -> ViewerOverrides {
        let renderer = |v: &str| crate::render::renderer_by_name(v).map(|r| r.name());
        ViewerOverrides {
            renderer: parsed(&get, "PINHOLE_RENDERER", renderer),
            split: parsed(&get, "PINHOLE_SPLIT", renderer),
            view: parsed(&get, "PINHOLE_VIEW", View::parse),
            gamma: get("PINHOLE_GAMMA").map(|v| switch(&v)),
            gi: parsed(&get, "PINHOLE_GI", GiMode::parse),
            spp: get("PINHOLE_SPP").and_then(|n| match n.parse::<u32>() {
                Ok(n) if (1..=4096).contains(&n) => Some(n),
                _ => {
                    eprintln!("pinhole: PINHOLE_SPP: expected 1 to 4096, got \"{n}\"");
                    None
                }
            }),
            select: get("PINHOLE_SELECT").and_then(|sel| {
                let xy: Vec<i64> = sel.split(',').filter_map(|v| v.trim().parse().ok()).collect();
                match xy[..] {
                    [x, y] => Some((x, y)),
                    _ => {
                        eprintln!("pinhole: PINHOLE_SELECT: expected X,Y, got \"{sel}\"");
                        None
                    }
                }
            }),
            zoom: get("PINHOLE_ZOOM").and_then(|z| z.parse::<f32>().map_err(|_| eprintln!("pinhole: PINHOLE_ZOOM: expected a number, got \"{z}\"")).ok()),
            vertices: get("PINHOLE_VERTICES").map(|v| switch(&v)),
            gallery: get("PINHOLE_GALLERY"),
            compare: get("PINHOLE_COMPARE").is_some_and(|v| switch(&v)),
            panels: get("PINHOLE_PANELS").map(|list| {
                let has = |n: &str| list.split(',').any(|p| p.trim() == n);
                OpenPanels { side: list.trim() != "none", camera: has("camera"), lights: has("lights"), materials: has("materials"), shading: has("shading") }
            }),
            bench_ui: get("PINHOLE_BENCH_UI"),
        }
    }
}

/// Variable `key` read through `get` and parsed; an error is reported and ignored.
fn parsed<T>(get: &impl Fn(&str) -> Option<String>, key: &str, parse: impl Fn(&str) -> Result<T, String>) -> Option<T> {
    get(key).and_then(|v| parse(&v).map_err(|e| eprintln!("pinhole: {key}: {e}")).ok())
}

/// An on/off variable: `0`, `off` and `false` are off, anything else on.
fn switch(v: &str) -> bool {
    !matches!(v, "0" | "off" | "false")
}

/// `PINHOLE_CACHE_DIR`, when set and not empty.
pub fn cache_dir() -> Option<PathBuf> {
    std::env::var_os("PINHOLE_CACHE_DIR").filter(|v| !v.is_empty()).map(PathBuf::from)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variables_parse_and_bad_values_are_ignored() {
        let table = [("PINHOLE_RENDERER", "rasterize"), ("PINHOLE_SPP", "0"), ("PINHOLE_SELECT", "3, 4"), ("PINHOLE_GAMMA", "off"), ("PINHOLE_PANELS", "shading,camera")];
        let o = ViewerOverrides::from_lookup(|k| table.iter().find(|(n, _)| *n == k).map(|(_, v)| v.to_string()));
        assert_eq!(o.renderer, Some(crate::render::raster::DEFAULT_RASTERIZE));
        assert_eq!((o.spp, o.select, o.gamma, o.compare), (None, Some((3, 4)), Some(false), false));
        assert_eq!(o.panels, Some(OpenPanels { side: true, camera: true, shading: true, ..Default::default() }));
        assert_eq!(ViewerOverrides::from_lookup(|_| None), ViewerOverrides::default());
    }
}
