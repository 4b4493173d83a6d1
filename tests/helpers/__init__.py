"""Code shared by the tests: seed tables, design files, the transcription of Appendix B.1.

Import it as ``from tests.helpers.<module> import ...`` (the repository root is on the test path).
"""
