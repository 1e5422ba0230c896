"""Readers and writers of the lab's file formats; nothing here depends on the analysis modules.

* :mod:`.atomic` - the one atomic writer (tables, figures, text, YAML; used by every writer);
* :mod:`.readers` - tidy TSV tables and YAML documents;
* :mod:`.c3d`, :mod:`.c3d_writer` - C3D motion capture (ezc3d);
* :mod:`.force_platforms` - C3D force platforms (ezc3d's platform extraction);
* :mod:`.opensim_tables` - TRC markers, .mot/.sto coordinates and external loads (OpenSim's adapters);
* :mod:`.osim` - OpenSim models and the quiet import of OpenSim;
* :mod:`.ik_tasks` - OpenSim IK task files;
* :mod:`.robot_log`, :mod:`.robot_log_mat` - the LOPER robot log (``loper-log 1``) and MATLAB exports;
* :mod:`.segment_table` - the swing-leg model's segment table (TSV, 10 significant digits);
* :mod:`.truth` - a synthetic subject's truth file (``truth.yaml``).
"""
