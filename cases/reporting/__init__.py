"""Reporting: a case's report, the document and figures it is drawn with, the scorecard and
rankings over the cases, the index's answers and the costs read from the bench."""
