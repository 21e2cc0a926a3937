"""The live view: the cell in 3D in a web browser, every signal live, inputs settable, run controls.

    twin view STATION [--host 127.0.0.1] [--port 8080]       the station, run by the view
    twin serve STATION --view [PORT]                         the same page beside the Modbus server
    twin view --replay FILE                                  a recording, with a timeline

Built on viser (a pip package that serves a three.js page over a websocket). The page is a front end
like the Modbus server: it reads the frames the stepping thread publishes (`twin.observe.scene`) and queues
writes for the next step; it never steps the twin and never calls pybullet itself.

`page` draws (scene, signals, state); `live` connects a page to a running twin (the `twin view` and
`twin serve --view` commands); `replay` plays a recording in the same page.
"""
