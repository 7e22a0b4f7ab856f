"""The job runner's common parts: the output folder a job owns (its record, the settings
that refuse a resume, the SHA-256 of its inputs and outputs, a fresh start, stale temporary
files) and the lock that keeps a second process out of it. See ``docs/output-folders.md``."""
from demfem.jobs.folder import (RECORD_FILES, OutputFolder, settings_differences,
                                sha256_file)
from demfem.jobs.lock import LOCK_FILE, FolderLock

__all__ = ["OutputFolder", "FolderLock", "LOCK_FILE", "RECORD_FILES", "settings_differences",
           "sha256_file"]
