"""MR damper models, the virtual benchmark damper, its virtual laboratory and identification."""
