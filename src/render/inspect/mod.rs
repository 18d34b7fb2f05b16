//! Seeing how a pixel was made: the recorder passed through the real code
//! path (`pixel_record`), its report (`pixel_report`), the debug views
//! (`debug`) and the wireframe overlay (`wireframe`).

pub mod debug;
pub mod pixel_record;
pub mod pixel_report;
pub mod wireframe;
