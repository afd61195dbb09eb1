//! Importers for capture files: C3D, OptiTrack Motive CSV, Vicon CSV and a plain CSV.
