//! (being written: issue 27)
