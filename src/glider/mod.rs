//! Planar 2-DOF glider mechanisms of the comparative study (Wenger, Gosselin, Chablat 2001).
