"""wormsim: worm gear drive dynamics with real tooth contact (MuJoCo), and the reduced wedge model.

Data flows one way: scenario -> geometry (meshgen) -> model -> simulation -> metrics -> recording/report.
"""
__version__ = "0.1.0"
