"""SSP 1.0 files: reading .ssd/.ssv/.ssm with schema checks (`reader`), writing them (`writer`),
and physical units (`units`)."""
