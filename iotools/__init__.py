"""Reading and writing files, apart from the physics (as pvlib's `iotools`).

`timetable` (CSV time tables), `weather` and `measurements` (the files of docs/guide.md),
`hourly` (EPW, TMY2, TMY3 hours), `typical_year` (the converter and its command line),
`combitimetable` (Modelica text tables), `table` (the `nodeforce table` conversion) and
`fmu_inputs` (the FMU's input table and start values, `nodeforce inputs`).
"""
