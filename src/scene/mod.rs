//! What the 3D view shows, as plain 2D marks: the orbit camera (`camera`), the marks
//! themselves (`marks`: lines, fills, discs, labels in pixels, colours as RGBA), the stage
//! drawn from the performance (`stage`: floor, drums with their membranes, the body with
//! its sticks), the colouring of the composed trajectories by speed or stroke phase
//! (`trail`), the timeline strip of a video frame (`strip`), and a software rasteriser
//! for the marks (`raster`, anti-aliased through tiny-skia, text through ab_glyph), and
//! the stage as lit triangles for the editor's depth-buffered GPU view (`solid`). The
//! editor's viewport paints the same marks with egui, and `exports::video` rasterises them
//! into video frames, so the view and the video are one drawing. Pure logic: no UI, no
//! audio device.

pub mod camera;
pub mod marks;
pub mod raster;
pub mod solid;
pub mod stage;
pub mod strip;
pub mod trail;
