"""``pkm serve``: pkm as a model and dynamics service over HTTP and WebSocket (the ``serve`` extra).

:func:`~pkm.serve.app.create_app` builds the ASGI application (FastAPI), :func:`~pkm.serve.app.serve` runs it with
uvicorn; :mod:`~pkm.serve.store` keeps the models (registered and uploaded), :mod:`~pkm.serve.queries` answers the
questions, :mod:`~pkm.serve.stream` the WebSocket streams. The client is :class:`pkm.client.Client`.
"""
