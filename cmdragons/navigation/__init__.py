"""Local navigators and grid navigation functions (the seeds' navigation catalogue)."""
