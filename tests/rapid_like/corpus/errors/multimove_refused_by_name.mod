! MultiMove synchronisation needs a second motion task: refused by name at its position.
! error: 6:5 SyncMoveOn belongs to MultiMove, which the twin cannot honour
! exit: 65
MODULE Sync
  PROC main()
    SyncMoveOn sync1, all_tasks;
  ENDPROC
ENDMODULE
