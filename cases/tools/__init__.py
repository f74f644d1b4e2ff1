"""Tools: what measures the code rather than the models' accuracy (the cost bench, the
optional engines it times, the FEM solver scaling). A tool uses the harness and the model,
never a case or a study."""
