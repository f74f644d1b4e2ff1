"""Each library case's report prose (a ``cases.framework.Narrative`` per case, named by its
``Case.narrative``): what was run, the opening, the findings and the case's own sections, kept
apart from the physics the case module declares."""
