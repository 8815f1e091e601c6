"""Run a masonry study (``sweep`` or ``optimize``) on a SLURM cluster.

dask-jobqueue starts a Dask scheduler in this process and submits SLURM jobs that each
start Dask workers; masonry's study runs against that scheduler (``--scheduler``), and
the jobs are cancelled when it ends. Run it on a login node (or in a small job of its
own), with ``--out`` on a file system every compute node reaches:

    pip install "masonry[slurm]"
    python examples/slurm_study.py --jobs 8 --account ACCOUNT --partition PARTITION \\
        --walltime 02:00:00 --setup "source ~/venvs/masonry/bin/activate" -- \\
        optimize study.toml --maximize load_factor --trials 200 --batch 8 \\
        --out /scratch/$USER/exports

``--dry-run`` prints the job script that would be submitted and submits nothing. Every
argument after ``--`` is masonry's. See docs/cli.md, "Studies on a SLURM cluster".
"""

import argparse
import sys


def parse(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--jobs", type=int, default=4,
                        help="SLURM jobs to submit (default 4)")
    parser.add_argument("--cores", type=int, default=1,
                        help="cores per job: one single-threaded worker per core (default 1)")
    parser.add_argument("--memory", default="4GB",
                        help="memory per job, shared by its workers (default 4GB)")
    parser.add_argument("--walltime", default="01:00:00",
                        help="each job's time limit, HH:MM:SS (default 01:00:00)")
    parser.add_argument("--account", help="the account charged (#SBATCH -A)")
    parser.add_argument("--partition", help="the partition (#SBATCH -p)")
    parser.add_argument("--interface", help="the network interface the scheduler and "
                                            "workers talk on, e.g. ib0 (default: Dask's)")
    parser.add_argument("--setup", action="append", default=[], metavar="LINE",
                        help="a shell line each job runs before its workers start, e.g. "
                             "'module load python' (repeatable)")
    parser.add_argument("--dry-run", action="store_true",
                        help="print the job script and submit nothing")
    parser.add_argument("masonry", nargs=argparse.REMAINDER,
                        help="-- then masonry's arguments: sweep STUDY.toml ... or "
                             "optimize STUDY.toml ...")
    args = parser.parse_args(argv)
    if args.masonry[:1] == ["--"]:
        args.masonry = args.masonry[1:]
    if not args.masonry and not args.dry_run:
        parser.error("give masonry's arguments after --, e.g. -- sweep study.toml")
    return args


def main(argv=None) -> int:
    args = parse(sys.argv[1:] if argv is None else argv)
    from dask_jobqueue import SLURMCluster

    # one single-threaded worker per core: a variant is one process (BLAS on one
    # thread), and variants are independent
    cluster = SLURMCluster(cores=args.cores, processes=args.cores, memory=args.memory,
                           walltime=args.walltime, account=args.account,
                           queue=args.partition, interface=args.interface,
                           job_script_prologue=args.setup, job_name="masonry-worker")
    try:
        if args.dry_run:
            print(cluster.job_script())
            return 0
        cluster.scale(jobs=args.jobs)
        from masonry_cli.main import main as masonry

        return masonry([*args.masonry, "--scheduler", cluster.scheduler_address])
    finally:
        cluster.close()


if __name__ == "__main__":
    sys.exit(main())
