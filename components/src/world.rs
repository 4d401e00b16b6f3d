//! World geometry data (owned by the world helper).
