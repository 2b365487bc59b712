# scenario sources
