//! Point-cloud attribute estimation.
