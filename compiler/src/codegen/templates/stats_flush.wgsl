    if ({{STATISTICS_ON}}) {
        workgroupBarrier();
        for (var k = mrsl_li; k < {{COUNTERS}}u; k += {{WORKGROUP}}u) {
            atomicAdd(&mrsl_stats[{{TARGET}}], atomicLoad(&mrsl_wg_stats[k]));
        }
    }
