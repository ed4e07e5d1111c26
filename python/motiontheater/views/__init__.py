"""Views of motions: the viewer page, curve plots, renders, marker and joint-position files."""
