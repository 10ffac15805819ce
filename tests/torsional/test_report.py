"""The torsional level's report.png and recording.rrd (wormsim.torsional.report), written from a short run, read
back."""

from __future__ import annotations

from tests._level_report import check_report_and_recording
from wormsim.torsional import report


def test_report_and_recording_are_written(tmp_path):
    check_report_and_recording("torsional", report, tmp_path)
