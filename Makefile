# Quick start: `make demo` and `make test` (see README.md). Both install missing Debian packages first.
SHELL := /bin/bash
MAKEFLAGS += --no-print-directory
# Debian's python3 must come first: catkin and the ROS tools need its modules (pyenv's python3 lacks them).
export PATH := /usr/bin:/bin:$(PATH)
export ROS_LANG_DISABLE := genlisp
export ROS_HOSTNAME ?= localhost
BUILD_DIR ?= build
# The devel space lives beside the build tree, not inside it: rosrun skips every path below <package>/build/, so
# a devel space under build/ made `rosrun picker_localisation <tool>` fail after `make`. $(BUILD_DIR)/devel is a
# symbolic link to it, so `source build/devel/setup.bash` still works.
DEVEL_DIR ?= $(abspath $(BUILD_DIR))-devel
JOBS ?= $(shell nproc)
BUILD_TYPE ?= Release
export ROS_HOME ?= $(CURDIR)/$(BUILD_DIR)/ros_home

.PHONY: all deps configure build test demo bench format clean

all: build

deps:
	@scripts/install_deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DCATKIN_DEVEL_PREFIX=$(DEVEL_DIR) \
	  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
	@if [ ! -L $(BUILD_DIR)/devel ]; then rm -rf $(BUILD_DIR)/devel; ln -s $(DEVEL_DIR) $(BUILD_DIR)/devel; fi

build: configure
	@cmake --build $(BUILD_DIR) -j$(JOBS) --target all tests

test: build
	@mkdir -p $(ROS_HOME)
	@cd $(BUILD_DIR) && ctest --output-on-failure -j$(JOBS) --timeout 900

demo: build
	@mkdir -p $(ROS_HOME)
	@scripts/demo.sh

bench: build
	@for b in $(BUILD_DIR)/devel/lib/picker_localisation/bench_*; do [ -x "$$b" ] && "$$b"; done

format:
	@find include src test -name '*.h' -o -name '*.cpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD_DIR) $(DEVEL_DIR)
