//! Fuzz targets live in `tests/`; see the repository README.
