"""Evaluation at scale: suites standing for the paper's datasets, a resumable sweep over them
(`tg-drake eval`), and every table of the paper's section VI derived from the sweep's records."""
