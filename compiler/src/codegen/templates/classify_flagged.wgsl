    var flagged = false;
    for (var j = 0; j < 4; j++) {
        flagged = flagged || (ok[j] && (mrsl_qflags{{WORD}}[j] & {{MASK}}u) != 0u);
    }
