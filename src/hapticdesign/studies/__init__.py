"""Studies: the seeds' pipelines end to end (``phantom`` = seed 000, ``rcube`` = seed 001), each ending in a report."""
