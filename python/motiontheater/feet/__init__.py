"""Feet: legs, the up axis and the floor; footplants and their table; the footskate cleanup and
its metrics."""
