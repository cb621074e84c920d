//! DICOM: segmentation objects (`seg`, on the grid `seg_grid` reads) and image series
//! (`series`), each file's declared lengths checked first (`lengths`, with `deflate` for a
//! deflated data set), its frames of pixels (`frames`) decoded by their codec (`rle`, `jpeg`,
//! `jpegls`, `jpeg2000`).

pub(in crate::io) mod deflate;
pub(in crate::io) mod frames;
pub(in crate::io) mod jpeg;
pub(in crate::io) mod jpeg2000;
pub(in crate::io) mod jpegls;
pub(in crate::io) mod lengths;
pub(in crate::io) mod rle;
pub(in crate::io) mod seg;
pub(in crate::io) mod seg_grid;
pub(in crate::io) mod series;
