"""Start Dask workers as SLURM jobs (dask-jobqueue, configured by jobqueue.yaml) and keep them up
while semsearch sends them runs. Run it on the login node, e.g. in tmux:

    DASK_CONFIG=examples/slurm python examples/slurm/cluster.py 4 > scheduler.txt

It writes the scheduler's address (tcp://HOST:PORT) on its first line; then, from the same node:

    semsearch run configs/hotel.yaml --executor dask --scheduler "$(head -1 scheduler.txt)"

Stop it with Ctrl-C: the jobs are cancelled. ``--print-job`` prints the batch script it would
submit, and submits nothing.
"""

import sys
import time

from dask_jobqueue import SLURMCluster

if __name__ == "__main__":
    cluster = SLURMCluster()  # every setting from jobqueue.slurm in the Dask configuration
    if "--print-job" in sys.argv:
        print(cluster.job_script())
        sys.exit(0)
    cluster.scale(jobs=int(sys.argv[1]) if len(sys.argv) > 1 else 4)
    print(cluster.scheduler_address, flush=True)
    try:
        while True:
            time.sleep(3600)
    finally:
        cluster.close()
