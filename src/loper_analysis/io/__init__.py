"""Readers and writers of the lab's file formats; nothing here depends on the analysis modules.

* :mod:`.atomic` - the one atomic writer (tables, figures, text, YAML; used by every writer);
* :mod:`.readers` - tidy TSV tables and YAML documents;
* :mod:`.c3d`, :mod:`.c3d_writer` - C3D motion capture (ezc3d);
* :mod:`.opensim_tables` - TRC markers and .mot/.sto coordinates (OpenSim's adapters);
* :mod:`.osim` - OpenSim models and the quiet import of OpenSim;
* :mod:`.ik_tasks` - OpenSim IK task files;
* :mod:`.robot_log`, :mod:`.robot_log_mat` - the LOPER robot log (``loper-log 1``) and MATLAB exports.
"""
