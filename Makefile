# Reproduction of classic comparator/plotter calibration papers by Monte-Carlo simulation.
# `make reproduce` and `make test` set everything up themselves (virtual environment, install).

# every path below is relative to the project: `make -f path/to/Makefile` from elsewhere was
# "No rule to make target 'pyproject.toml'"; say where to run it instead
ifeq ($(wildcard pyproject.toml sim/__init__.py),)
$(error $(lastword $(MAKEFILE_LIST)) runs in its own directory: make -C <its directory> $(or $(MAKECMDGOALS),help))
endif

# A variable on make's command line that this Makefile does not read but is named like what it
# reads was dropped without a word: `make verify STUDY=brown_table1` re-ran every study,
# `make reproduce JOBS=4` ran 2 at a time, `make test PYTEST_ARGS=-x` ran every test. One line
# naming what to write instead, exit 2 (set in the environment such a name is left alone).
not_read = $(if $(filter command line,$(origin $(1))),$(error make: $(1) is not a setting of this Makefile; $(2)))
# $(call not_read_any,NAMES,TEXT): not_read of each of NAMES, the spellings a user tries for a
# setting (singular or plural, without its prefix, in lower case: `make test workers=1`)
not_read_any = $(foreach n_,$(1),$(call not_read,$(n_),$(2)))
$(call not_read_any,STUDY study,make verify VERIFY_FLAGS="--study NAME" re-runs one study)
$(call not_read_any,STUDIES studies,make verify VERIFY_FLAGS="--study NAME --study NAME2" re-runs those studies)
$(call not_read_any,JOBS JOB RUN_JOB jobs run_jobs,RUN_JOBS=N runs N studies at a time (make reproduce and make rerun))
$(call not_read_any,WORKERS WORKER workers,TEST_WORKERS=N (make test) or MUTATION_WORKERS=N or RUN_FLAGS="--workers N")
$(call not_read_any,TEST_WORKER test_workers,TEST_WORKERS=N runs the tests in N processes (make test))
$(call not_read_any,MUTATION_WORKER mutation_workers,MUTATION_WORKERS=N (make mutation))
$(call not_read_any,TRIALS TRIAL trials,RUN_FLAGS="--trials N" (make reproduce and make rerun) or VERIFY_FLAGS="--trials N")
$(call not_read_any,SEED SEEDS seed,RUN_FLAGS="--seed N" (make reproduce and make rerun) or FUZZ_SEED=N (make fuzz))
$(call not_read_any,FUZZ_SEEDS fuzz_seed,FUZZ_SEED=N (make fuzz))
$(call not_read_any,CASES FUZZ_CASE cases fuzz_cases,FUZZ_CASES=N (make fuzz))
$(call not_read_any,SAVE fuzz_save save,FUZZ_SAVE=DIR (make fuzz))
$(call not_read_any,FLAGS ARGS flags args,RUN_FLAGS or VERIFY_FLAGS or BENCH_FLAGS: the options of the target's command)
$(call not_read_any,RUN_FLAG RUN_ARGS run_flags,RUN_FLAGS="..." (make reproduce and make rerun))
$(call not_read_any,VERIFY_FLAG VERIFY_ARGS verify_flags,VERIFY_FLAGS="..." (make verify))
$(call not_read_any,BENCH_FLAG BENCH_ARGS bench_flags,BENCH_FLAGS="..." (make bench))
$(call not_read_any,OUT BENCH_DIR out bench_out,BENCH_OUT=DIR (make bench))
$(call not_read_any,PYTEST_ARGS PYTEST_FLAGS PYTEST_OPTS,PYTEST_ADDOPTS="..." passes options to pytest (make test))
$(call not_read_any,PY python,PYTHON=python3.X chooses the Python of the virtual environment (make venv))
# the settings spelt without their underscore or with a hyphen, in either case (`make verify
# VERIFYFLAGS="--study NAME"` re-ran every study, `make test TESTWORKERS=0` ran 2 processes)
lower = $(subst Z,z,$(subst Y,y,$(subst X,x,$(subst W,w,$(subst V,v,$(subst U,u,$(subst T,t,$(subst S,s,$(subst R,r,$(subst Q,q,$(subst P,p,$(subst O,o,$(subst N,n,$(subst M,m,$(subst L,l,$(subst K,k,$(subst J,j,$(subst I,i,$(subst H,h,$(subst G,g,$(subst F,f,$(subst E,e,$(subst D,d,$(subst C,c,$(subst B,b,$(subst A,a,$(1)))))))))))))))))))))))))))
# a comma inside a $(call ...) argument ($(call) splits its arguments at commas)
comma := ,
SETTINGS := PYTHON RUN_FLAGS RUN_JOBS TEST_WORKERS MUTATION_WORKERS VERIFY_FLAGS BENCH_FLAGS \
  BENCH_OUT FUZZ_CASES FUZZ_SEED FUZZ_SAVE
misspelt = $(filter-out $(1),$(sort $(subst _,,$(1)) $(subst _,-,$(1)) $(call lower,$(subst _,,$(1)) $(subst _,-,$(1)))))
$(foreach s_,$(SETTINGS),$(call not_read_any,$(call misspelt,$(s_)),$(s_)="..." is the spelling))
# The Makefile's own names given on make's command line replaced its paths and rules without a
# word: `make clean VENV=results` removed the committed results/ (`rm -rf results ...`),
# `make test STAMP=x` or `make reproduce STUDIES=...` ran on misread names. One line, exit 2
# (each is checked by its origin here, before any of them is used).
OWN_NAMES := VENV STAMP INSTALLING PIP_LOG VENV_LOCK VENV_USABLE MADE_IN MADE_FROM PYPROJECT_SUM \
  PYPROJECT_DEP INSTALLED_NOW INSTALLED_AT_START STUDY_FILES STUDIES SETTINGS OWN_NAMES newline comma \
  q whole shellwords locked pip lower misspelt not_read not_read_any venv_lacks VENV_CHECK MAKE_JOBS
$(foreach v_,$(OWN_NAMES),$(if $(filter command line,$(origin $(v_))),$(error make: $(v_) is \
  this Makefile's own name and not a setting (the settings: $(SETTINGS)); leave it off)))
# A line break in a setting (RUN_FLAGS=$$'--seed 3\n--trials 40', from a script or a pasted
# line) split the recipe's command into two: "/bin/sh: 1: Syntax error: Unterminated quoted
# string", naming no variable. One line naming it, exit 2.
define newline


endef
$(foreach s_,$(SETTINGS),$(if $(findstring $(newline),$(value $(s_))),$(error make: $(s_) \
  holds a line break: give its value on one line)))

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
RUN_FLAGS ?= --workers 1
STUDY_FILES := $(wildcard studies/*.toml)
STUDIES := $(basename $(notdir $(STUDY_FILES)))
# every `python -m sim ...` is a fresh process: let Python keep the compiled modules
# (__pycache__) even where the environment asks it not to, or each run compiles them again
unexport PYTHONDONTWRITEBYTECODE

.DEFAULT_GOAL := help
.PHONY: help venv test reproduce rerun verify report bench clean fuzz mutation venv-unusable pyproject-changed
.PHONY: venv-incomplete

# $(call q,TEXT): TEXT as one single-quoted shell word (a value with spaces or quotes stays one)
q = '$(subst ','\'',$(1))'
# $(call whole,NAME,MIN): stop with one line unless the variable NAME is a whole number >= MIN
# (RUN_JOBS= or TEST_WORKERS=abc reached the command as a misread argument, or after the install)
whole = @case $(call q,$($(1))) in ''|*[!0-9]*) false;; *) test $(call q,$($(1))) -ge $(2);; esac || \
	{ printf 'make %s: %s must be a whole number of at least %s (got %s)\n' $@ $(1) $(2) $(call q,'$($(1))') >&2; exit 2; }
# $(call shellwords,NAME): stop with one line unless the variable NAME (options passed on as they
# are, several words) is words the shell can read: RUN_FLAGS='--set "x' broke the command line
# ("/bin/sh: Syntax error: Unterminated quoted string", naming no variable)
shellwords = @sh -nc $(call q,: $($(1))) 2>/dev/null || \
	{ printf 'make %s: %s is not words the shell can read (a quote left open?) (got %s)\n' $@ $(1) $(call q,'$($(1))') >&2; exit 2; }

help: ## list the targets
	@grep -E '^[a-zA-Z_%/.-]+:.*## ' $(MAKEFILE_LIST) | sed -E 's/:.*## /\t/' | sort | \
	  awk -F'\t' '{printf "  %-22s %s\n", $$1, $$2}'

# A .venv that cannot serve this directory is made again from scratch, whatever its stamp says,
# so that `make venv` repairs it (each needed `make clean` first): its Python no longer starts
# (bin/python deleted, the Python it was made from removed: ".venv/bin/python: No such file or
# directory"), is older than pyproject.toml's requires-python (a `make venv PYTHON=python3.10`
# that failed), or the stamp names another directory (the project moved or copied with its
# .venv, whose scripts start the old path's Python and code). The stamp holds the directory,
# then the checksum of the pyproject.toml installed: whether it changed since is decided by its
# content, not by file times (a pyproject.toml dated in the future, by clock skew or a copy
# from a machine whose clock is ahead, made every target install again, and fail offline, until
# the clock caught up; one edited while the clock stood behind the stamp's was not installed).
# A stamp of an older Makefile (the directory alone) is judged by its time, as before.
# An install that failed or was interrupted (a Ctrl-C during pip's own upgrade left a pip that
# no longer imports; one during `venv --clear` half a .venv) leaves its mark INSTALLING beside
# the .venv, which only a finished install removes: made again from scratch too. A .venv of
# the user's own (no mark) is installed into as it is. The mark holds venv's own output (a
# PYTHON that is missing or cannot make one, python2.7: one line; Ctrl-C: no traceback).
# A .venv that is a file or a link to nothing (not the suite's) was "PYTHON (python3) could not
# make .venv: Error: [Errno 20] Not a directory", blaming PYTHON: it is named, and left alone.
INSTALLING := $(VENV).installing
VENV_USABLE := $(shell $(PY) -S -c 'import sys; sys.exit(sys.version_info < (3, 11))' >/dev/null 2>&1 && echo yes)
MADE_IN := $(shell sed -n 1p $(STAMP) 2>/dev/null)
MADE_FROM := $(shell sed -n 2p $(STAMP) 2>/dev/null)
PYPROJECT_SUM := $(shell cksum < pyproject.toml | tr ' ' -)
# nothing when the stamp's checksum is pyproject.toml's, pyproject.toml when it records none
PYPROJECT_DEP := $(if $(MADE_FROM),$(if $(filter $(PYPROJECT_SUM),$(MADE_FROM)),,pyproject-changed),pyproject.toml)
VENV_USABLE := $(and $(VENV_USABLE),$(if $(MADE_IN),$(if $(subst $(CURDIR),,$(MADE_IN)),,yes),yes))
VENV_USABLE := $(and $(VENV_USABLE),$(if $(wildcard $(INSTALLING)),,yes))
# A .venv installed (its stamp current) that no longer holds what pyproject.toml asks for (a
# library removed or replaced since: `pip uninstall pyarrow`) was taken for whole: every target
# failed in it (pytest's collection errors, "No such file or directory: .venv/bin/ruff") and
# `make venv` did nothing. sim/venv_check.py names what it lacks (decided when site-packages
# changed after the stamp: pip touches it), and the project is installed into it again.
VENV_CHECK := $(if $(wildcard sim/venv_check.py),$(PY) -I sim/venv_check.py)
venv_lacks := $(if $(and $(VENV_CHECK),$(VENV_USABLE),$(MADE_FROM),$(shell find $(VENV)/lib \
  -maxdepth 2 -name site-packages -newer $(STAMP) 2>/dev/null)),$(shell $(VENV_CHECK) 2>&1))
# pip (its arguments: at its definition below): its output kept in PIP_LOG; a failure (no network,
# no index, a Python the project does not support) is one line with pip's first error (else its
# last line: a pip that does not start), exit 2 (not pip's dozen lines); `make venv` tries again
PIP_LOG := $(VENV)/pip.log
# Each install step holds the lock VENV_LOCK (where flock(1) exists): a pip still rolling back
# after a Ctrl-C, or a second `make venv` at once, is waited for instead of racing the next
# step ("venv --clear: Directory not empty", or a pip left without its modules). The lock file
# stays (removed while another make waited on it, a third make locked a new file beside it).
VENV_LOCK := $(if $(shell command -v flock 2>/dev/null),flock $(VENV).lock)
# A step of the install checks, under the lock, whether another make finished the install while
# this one waited (two terminals or `make -j` on a fresh clone: `make venv` and `make test`):
# the stamp is now current, and it was not when this make started. It then does nothing: its
# `venv --clear` wiped the finished .venv while the other make went on to run the tests in it
# ("No such file or directory: .venv/bin/ruff"). The last pip step writes the stamp under the
# same lock, so no step of another make runs between the install and its stamp.
INSTALLED_NOW = test -f $(STAMP) && test "$$(sed -n 2p $(STAMP))" = $(PYPROJECT_SUM) && \
	test "$$(sed -n 1p $(STAMP))" = $(call q,$(CURDIR)) && test ! -e $(INSTALLING)
INSTALLED_AT_START := $(and $(VENV_USABLE),$(MADE_IN),$(if $(PYPROJECT_DEP),,yes))
# $(call locked,SCRIPT,SKIP): a prefix that runs the command after it as "$$@" in the shell
# SCRIPT under the lock; SKIP (the stamp's steps): nothing when another make installed meanwhile
locked = $(VENV_LOCK) sh -c $(call q,$(if $(and $(2),$(if $(INSTALLED_AT_START),,yes)),$(INSTALLED_NOW) && exit 0;) $(1)) sh
# $(call pip,ARGS[,SKIP,THEN]): pip install ARGS under the lock; SKIP non-empty (the stamp's steps):
# nothing when another make installed meanwhile; THEN: a shell command run, still locked, on success
pip = @$(call locked,"$$@" >> $(PIP_LOG) 2>&1 || exit; $(3),$(2)) $(PY) -m pip install --quiet $(1) || { printf 'make: pip could not install into $(VENV): %s (all of its output: $(PIP_LOG))\n' \
	"$$({ grep -m1 -E '^ *ERROR' $(PIP_LOG) || grep -v '^ *$$' $(PIP_LOG) | tail -1; } | sed -E 's/^ *(ERROR: *)?//')" >&2; exit 2; }

$(STAMP): $(PYPROJECT_DEP) $(if $(VENV_USABLE),,venv-unusable) $(if $(venv_lacks),venv-incomplete)
	$(if $(venv_lacks),@printf 'make: %s: installing the project again\n' $(call q,$(venv_lacks)))
	@test -d $(VENV) || ! { test -e $(VENV) || test -L $(VENV); } || { printf 'make: %s is %s, not a virtual environment: %s\n' \
	  $(VENV) 'not a directory (a file, or a link to nothing)' 'remove or rename it, then make venv' >&2; exit 2; }
	@$(if $(VENV_USABLE),:,test ! -L $(VENV)) || { printf 'make: %s is a link to %s, %s: it is not made again through the link (venv --clear would empty it there); remove the link, then make venv\n' \
	  $(VENV) "$$(readlink -f $(VENV))" $(call q,$(if $(and $(MADE_IN),$(subst $(CURDIR),,$(MADE_IN))),a virtual environment made for $(MADE_IN),not a usable virtual environment here)) >&2; exit 2; }
	@echo "making $(VENV) and installing the project and its libraries (pip; its output goes to $(PIP_LOG))"
	@$(call locked,"$$@" > $(INSTALLING) 2>&1,skip) $(call q,$(PYTHON)) -m venv $(if $(VENV_USABLE),,--clear) $(VENV) || { rc=$$?; \
	  test $$rc -gt 128 && exit $$rc; printf 'make: PYTHON (%s) could not make $(VENV): %s\n' $(call q,$(PYTHON)) \
	  "$$(grep -v '^ *$$' $(INSTALLING) | tail -1)" >&2; exit 2; }
	@test -e $(INSTALLING) || exit 0; : > $(PIP_LOG)
	$(call pip,--upgrade pip,skip)
	$(call pip,-e ".[dev]",skip,$(if $(VENV_CHECK),$(VENV_CHECK) --after-pip >> $(PIP_LOG) &&) printf '%s\n%s\n' $(call q,$(CURDIR)) $(PYPROJECT_SUM) > $(STAMP) && rm -f $(INSTALLING))

venv: $(STAMP) ## create the virtual environment and install the project (with PYTHON=python3, 3.11 or later)

# The test files run side by side on TEST_WORKERS processes (pytest-xdist), a file on one process
# (its module fixtures, such as the shared Dask cluster, start once); TEST_WORKERS=0: one process.
# The slowest files are handed out first (tests/conftest.py SLOW_FIRST; --no-loadscope-reorder
# keeps that order). SIM_TEST_CPU_LOG=FILE logs each test's CPU seconds (where the time goes).
TEST_WORKERS ?= 2

test: $(STAMP) ## lint (ruff), the layer contracts (import-linter), then the test suite on TEST_WORKERS=2 processes
	$(if $(filter auto logical,$(TEST_WORKERS)),,$(call whole,TEST_WORKERS,0))
	$(VENV)/bin/ruff check sim tests benchmarks
	$(VENV)/bin/ruff format --check sim tests benchmarks
	$(VENV)/bin/lint-imports
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder

# The tests marked long (tests/conftest.py: many seconds each, a faster test of the same class
# runs in make test) are skipped by make test and run here, after the fuzz; none marked is
# pytest's exit 5 ("no tests ran"), which failed make fuzz after its fuzz had passed.
# FUZZ_CASES and FUZZ_SEED are whole numbers (FUZZ_CASES=0 or -1 fuzzed nothing and passed;
# FUZZ_CASES=abc was a pytest collection error)
fuzz: $(STAMP) ## long fuzz of study files, overrides and options (FUZZ_CASES=300, FUZZ_SEED, FUZZ_SAVE), then the tests marked long
	@case "$${FUZZ_CASES:-300}" in *[!0-9]*) false;; *) test "$${FUZZ_CASES:-300}" -ge 1;; esac || \
	  { echo "make fuzz: FUZZ_CASES must be a whole number of at least 1 (got '$${FUZZ_CASES}')" >&2; exit 2; }
	@case "$${FUZZ_SEED:-13}" in *[!0-9]*) echo "make fuzz: FUZZ_SEED must be a whole number (got '$${FUZZ_SEED}')" >&2; exit 2;; esac
	FUZZ_CASES=$${FUZZ_CASES:-300} $(PY) -m pytest tests/test_fuzz.py -p no:cacheprovider
	$(if $(filter auto logical,$(TEST_WORKERS)),,$(call whole,TEST_WORKERS,0))
	SIM_LONG_TESTS=1 $(PY) -m pytest -m long -n $(TEST_WORKERS) --dist loadfile -p no:cacheprovider || test $$? -eq 5

# Mutation testing of the verdict rules and interval methods ([tool.mutmut] in pyproject.toml);
# not part of `make test`: about 10-20 minutes on 2 cores. Writes docs/mutation.md.
MUTATION_WORKERS ?= 2

mutation: $(STAMP) ## mutate the verdict rules, intervals and region verdicts (sim/claims/), run their tests, write docs/mutation.md (MUTATION_WORKERS=2)
	$(call whole,MUTATION_WORKERS,1)
	$(call pip,-e ".[dev$(comma)mutation]")
	rm -rf mutants
	$(VENV)/bin/mutmut run --max-children $(MUTATION_WORKERS) > /dev/null
	$(PY) tests/mutation_report.py

# A study is re-run when its results are not current: run.json must record the study file's
# config and the hash of the code that study imports (sim/mc/codehash.py). Decided by content,
# not by file times, so a fresh clone re-runs nothing that is current. The studies run
# RUN_JOBS at a time, each in its own process with RUN_FLAGS (sim/batch.py; quiet when
# RUN_JOBS > 1, the slowest first). Two studies of one worker each keep both cores busy, as
# fast as two of two workers each and without their pools (results/bench/rerun.parquet).
# The batch rebuilds the report (--report), after a failed or interrupted batch too when a run
# published: make stopped before `sim report` when one study's run failed or was killed, and
# REPORT.md kept the old claims of the studies that had published (sim/batch_report.py).
# make's own -jN (`make -j4 reproduce`) ran 2 studies at a time without a word: it is how many
# run at a time when RUN_JOBS is not given (RUN_JOBS=N wins; -j without a number keeps 2).
# MFLAGS holds make's options alone: MAKEFLAGS holds the command line's variables too, and a
# word "-j9" in one of their values (RUN_FLAGS="... -j9") was taken for make's -j. At most
# sim.batch's 64: `make -j$(nproc) reproduce` on a machine of more cores was refused ("--jobs:
# must be <= 64"), naming an option the user never gave
MAKE_JOBS = $(patsubst -j%,%,$(filter -j%,$(MFLAGS)))
RUN_JOBS ?= $(if $(MAKE_JOBS),$(shell test $(MAKE_JOBS) -le 64 && echo $(MAKE_JOBS) || echo 64),2)

reproduce: $(STAMP) ## run every study whose results are out of date, then rebuild results/REPORT.md (RUN_JOBS=2 at a time, or make -jN's N up to 64, each with RUN_FLAGS="--workers 1": sim run options)
	$(call whole,RUN_JOBS,1)
	$(call shellwords,RUN_FLAGS)
	$(PY) -m sim.batch --stale-only --report --jobs $(RUN_JOBS) --results results $(STUDY_FILES) -- $(RUN_FLAGS)

rerun: $(STAMP) ## re-run every study even if its results are up to date, then the report (RUN_JOBS, RUN_FLAGS)
	$(call whole,RUN_JOBS,1)
	$(call shellwords,RUN_FLAGS)
	$(PY) -m sim.batch --report --jobs $(RUN_JOBS) --results results $(STUDY_FILES) -- $(RUN_FLAGS)

# VERIFY_FLAGS: e.g. "--study brown_table1", "--scratch DIR" (see python -m sim.report.verify -h;
# results of your own study files: python -m sim.report.verify --results DIR --studies DIR).
# A failed comparison (exit 1) rebuilds the report too: REPORT.md showed the record before it
# SIM_STOP_WITH_PARENT=$$$$ (the recipe's shell): SIGTERM to make ends that shell only, and
# verify ran on, orphaned; it now ends with the shell (sim.mc.children.die_with_parent)
VERIFY_FLAGS ?=

verify: $(STAMP) ## re-run every study into a scratch directory and compare with results/ (a rule per kind of column; VERIFY_FLAGS)
	$(call shellwords,VERIFY_FLAGS)
	SIM_STOP_WITH_PARENT=$$$$ $(PY) -m sim.report.verify --results results --workers 2 $(VERIFY_FLAGS) || { rc=$$?; \
	  [ $$rc -ne 1 ] || SIM_STOP_WITH_PARENT=$$$$ $(PY) -m sim report --results results; exit $$rc; }
	$(PY) -m sim report --results results

report: $(STAMP) ## rebuild results/REPORT.md and every results/<study>/README.md from the Parquet files alone
	$(PY) -m sim report --results results

# BENCH_FLAGS: e.g. "--quick" (a smoke run: small sizes, tiny study configurations),
# "--no-rerun" (leave out the make rerun rows), "--only engines"; see python -m benchmarks -h
BENCH_FLAGS ?=
# a smoke run (--quick) never replaces the committed measurements of results/bench
BENCH_OUT ?= $(if $(filter --quick,$(BENCH_FLAGS)),scratch/bench-quick,results/bench)

bench: $(STAMP) ## time the solvers against SciPy loops, and make rerun with 1 and 2 workers (results/bench/, or BENCH_OUT; BENCH_FLAGS=--quick: smoke, into scratch/bench-quick/)
	$(call shellwords,BENCH_FLAGS)
	$(if $(filter --out --out=%,$(BENCH_FLAGS)),@echo 'make bench: BENCH_FLAGS holds --out: give the directory as BENCH_OUT=DIR' >&2; exit 2)
	$(PY) -m benchmarks --out $(call q,$(BENCH_OUT)) $(BENCH_FLAGS)

clean: ## remove the virtual environment and caches (results/ is kept)
	rm -rf $(VENV) $(VENV).installing $(VENV).lock .pytest_cache sim.egg-info mutants

# A target the Makefile does not have (`make tset`, `make verfiy`, `make reproduce-n`) was make's
# "No rule to make target 'tset'.  Stop.", naming none it has: one line listing them, exit 2.
# A missing file another target needs (pyproject.toml) is named as missing. The phony steps of
# the install have empty rules, or this recipe would run for them.
venv-unusable pyproject-changed venv-incomplete: ;
.DEFAULT:
	@$(if $(filter $@,$(MAKECMDGOALS)),printf 'make: %s is not a target of this Makefile (its targets: %s; make help says what each does)\n' \
	  $(call q,$@) $(call q,$(shell sed -nE 's/^([a-z]+):.*## .*/\1/p' $(firstword $(MAKEFILE_LIST)) | tr '\n' ' ' | sed 's/ $$//')), \
	  printf 'make: %s is missing (make %s needs it)\n' $(call q,$@) $(call q,$(or $(MAKECMDGOALS),help))) >&2; exit 2
