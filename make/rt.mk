# Ray tracing (optional extra): Sionna RT 2.2.0 on Dr.Jit's CPU (LLVM) backend. Included from the
# Makefile, whose $(PY) and $(VENV) and `install` target it uses.
#
#   make rt-deps    Debian's libllvm19 (apt, only when missing) + pip install -e '.[rt]'
#
# Dr.Jit needs LLVM >= 15, and LLVM 15/16 abort in Sionna's first path computation ("LLVM ERROR:
# Cannot select ... fmaximum"), so we use Debian 12's libllvm19. tunnelkit.rt points Dr.Jit at
# /usr/lib/<multiarch>/libLLVM.so.19.1 on import when DRJIT_LIBLLVM_PATH is unset; set the variable
# yourself for an LLVM >= 17 elsewhere. Without root, apt runs through sudo when available.

RT_STAMP := $(VENV)/.rt-stamp
SUDO := $(if $(filter 0,$(shell id -u)),,$(shell command -v sudo))

.PHONY: rt-deps rt-llvm

rt-deps: rt-llvm $(RT_STAMP)

rt-llvm:
	@if ls /usr/lib/*-linux-gnu/libLLVM.so.19.1 >/dev/null 2>&1; then :; \
	elif command -v apt-get >/dev/null 2>&1; then \
		echo "installing Debian's libllvm19 (Dr.Jit CPU backend for Sionna RT)"; \
		$(SUDO) $(APT_LOCKED) update -qq && $(SUDO) $(APT_LOCKED) install -y -qq libllvm19 >/dev/null; \
	else \
		echo "rt-llvm: no apt-get here; install LLVM >= 17 and set DRJIT_LIBLLVM_PATH to its libLLVM.so" >&2; \
	fi

$(RT_STAMP): pyproject.toml | install
	$(PY) -m pip install --quiet -e '.[rt]' 2>&1 | $(PIP_FILTER)
	$(PY) -c "from tunnelkit import rt; rt.require_sionna(); print('Sionna RT ready')"
	touch $(RT_STAMP)
