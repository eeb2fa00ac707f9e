"""Identification of MR damper models from periodic tests (Ikhouane–Rodellar, Rodríguez, Bahar et al. 2009)."""
