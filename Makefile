# Thin wrappers; dev.sh does the work so that a machine without make works too.
.PHONY: setup lab test bench
setup:
	./dev.sh setup
lab:
	./dev.sh lab
test:
	./dev.sh test
bench:
	./dev.sh bench
