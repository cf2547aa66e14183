"""Files out: identification results on disk (:mod:`~dynid.export.result_files`), written whole
into checked output folders (:mod:`~dynid.export.output_folder`), with their plots
(:mod:`~dynid.export.plots`) and the text summary of a model (:mod:`~dynid.export.summary`)."""
