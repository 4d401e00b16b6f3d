//! Occupancy map data (owned by the mapping helper; see systems/src/mapping).
