"""Characters: alias tables of known rigs and joint maps; retargeting a take onto another
skeleton."""
