"""One function over many tasks (vares/parallel.py): here, or on worker processes, in the tasks'
order, with the number of workers that ran them (a laminate's plies, a band's samples)."""

import operator

from vares.parallel import parallel_map


def test_here_and_on_worker_processes_alike():
    tasks = [-3, 2, -1, 5, -4]
    here = parallel_map(abs, tasks)
    assert here == ([3, 2, 1, 5, 4], 1)
    assert parallel_map(abs, tasks, workers=1) == here
    assert parallel_map(abs, tasks, workers=2) == ([3, 2, 1, 5, 4], 2)
    assert parallel_map(operator.neg, [], workers=2) == ([], 2)
