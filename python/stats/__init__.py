"""calligraphy.stats: a study's tables, its statistics and its report page, in pure Python.

Modules (each imported on its own; importing the package imports none of them):

* ``study``: a study's tidy tables (``load``, ``Study``, traces, ``propose_characters``; pandas);
* ``statistics``: the statistics a lab publishes (SciPy, statsmodels);
* ``mixed_models``: linear mixed models by R's lme4 and lmerTest (``Rscript lmer_fit.R``);
* ``design_models``: what the designs share (``StudyDesign``, the question rows, Holm, scaled and reduced fits);
* ``design_analysis``: the questions of a study's design (training, ANCOVA, Holm);
* ``crossover_analysis``: a crossover study's questions (period, same-set pre-test, carry-over);
* ``study_report``: the study report that reads like a paper (``python3 -m calligraphy.study_report``);
* ``fonts``: a CJK font for matplotlib's figures.

Layering: the modules import one another in one direction only (statistics and mixed_models at the bottom,
then design_models, crossover_analysis, design_analysis, study, study_report), and nothing of ``calligraphy``
outside this package except through ``_native``, the one door to the C++ extension. The bindings' modules
(``frames``, ``metrics``, ``experiments``, ``cohort``, ``plot``) may import this package, never the reverse.
The old paths (``calligraphy.statistics``, ``calligraphy.study``, ``calligraphy.study_report``, ...) are the
same module objects (docs/python.md).
"""

__all__ = ["crossover_analysis", "design_analysis", "design_models", "fonts", "mixed_models", "statistics", "study",
           "study_report"]
