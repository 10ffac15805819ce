"""What a run returns and reports: result (the Result every level returns), summary_keys (every summary.json key:
unit, meaning, sign), metrics (the summary from the time series), run_warnings, report_header (report.png's header),
recording (rerun .rrd), provenance (the measured records under docs/data/)."""
