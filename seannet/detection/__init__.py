"""A detector in the loop: boxes from pixels, trained on the dataset's own COCO
export, lifted to 3D with the depth channel and turned into scene graphs by the generator's
relation rules, so a localizer can be measured without the generator's annotations."""
