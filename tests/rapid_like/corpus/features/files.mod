! Files: Open ... \Write and Write put lines in a file (traced as "file" events, not written to disk),
! Open ... \Read and ReadStr read them back line by line, "EOF" at the end. WaitSyncTask and PDispOn
! are accepted (one task; no displacement).
! trace: {"t": 0.0, "type": "file", "file": "HOME:/log.txt", "text": "parts: 3\n"}
! trace: {"t": 0.0, "type": "file", "file": "HOME:/log.txt", "text": "done\n"}
! trace: {"t": 0.0, "type": "print", "text": "read back: parts: 3"}
! trace: {"t": 0.0, "type": "print", "text": "then: done"}
! trace: {"t": 0.0, "type": "print", "text": "eof: EOF"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE FileLog
  VAR iodev logfile;
  VAR num nParts := 3;
  PERS tasks task_list{2} := [["T_ROB1"], ["T_ROB2"]];
  VAR syncident sync1;
  PROC main()
    Open "HOME:" \File:="log.txt", logfile \Write;
    Write logfile, "parts: " \Num:=nParts;
    Write logfile, "done";
    Close logfile;
    Open "HOME:/log.txt", logfile \Read;
    TPWrite "read back: " + ReadStr(logfile);
    TPWrite "then: " + ReadStr(logfile);
    TPWrite "eof: " + ReadStr(logfile);
    Close logfile;
    WaitSyncTask sync1, task_list;
    PDispOn \ExeP:=CRobT(), CRobT(), tool0;
  ENDPROC
ENDMODULE
