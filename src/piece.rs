//! Smooth pieces (SPEC §3–4): piece equations, guards, tangents and orientation.
