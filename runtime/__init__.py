"""The runtime plumbing every layer may use, the physics included: temporary folders that name
their owner (`tempdirs`), worker processes and how a run ends (`lifetime`), the Dask cluster
(`cluster`) and the C compiler (`compiler`). It imports nothing of nodeforce's but the error type
of bad input (`model.errors`, which the Python FMU carries with the physics)."""
