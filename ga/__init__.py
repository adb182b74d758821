"""The forcing search of Lauret et al.: which measured nodes, forced, bring the model to the data.

ga.search.search is the entry point; ga.evaluation holds the evaluator interface and the
parallel backends.
"""
