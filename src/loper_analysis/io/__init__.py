"""Readers and writers of the lab's file formats (robot logs; C3D/TRC later)."""
