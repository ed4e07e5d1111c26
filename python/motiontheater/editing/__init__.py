"""The steps that edit motions: filters, interpolators, signal processing, conversion between
conventions, the combiner and its scenes, pipelines of steps and their streaming over takes of
any length."""
