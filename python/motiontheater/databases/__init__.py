"""Whole databases: batches of takes on all cores or a Dask cluster, with progress, a manifest
and reports."""
