"""mpmvv's reports: results files and suite directories read (results), norms and
observed orders (norms, orders, series), the gate (gate) and the report
(report, with its rows, tables and figures). Run as modules from the project's
root, `/usr/bin/python3 -m reports.report DIR`, or through `mpmvv report` and
`mpmvv gate`."""
