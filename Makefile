# Thin wrappers; dev.sh does the work so that a machine without make works too.
.PHONY: setup demo test bench
setup:
	./dev.sh setup
demo:
	./dev.sh demo
test:
	./dev.sh test
bench:
	./dev.sh bench
