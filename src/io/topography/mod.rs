//! AFM and profilometer height maps (placeholder, filled below).
